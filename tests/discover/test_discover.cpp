// Discover on a short simulated recording (smooth motion of the shoulder rig, no
// targets given) against the simulator's truth: every body with all but at most one of
// its markers, no marker in a wrong body, the topology and joint types, ball centres
// within 0.5 mm and hinge axes within 0.3 deg in world terms (discover_truth.h).
#include <gtest/gtest.h>

#include <map>

#include "discover/frame_points.h"
#include "discover/point_tracker.h"
#include "discover_truth.h"
#include "sim/simulate.h"
#include "track/truth.h"
#include "tests/support/test_support.h"

namespace mocap {
namespace {

class DiscoverSim : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = new test::TempDir("discover_sim");
    sim::SimOptions o;
    o.frames = 160;
    o.seed = 7;
    auto s = sim::write_simulated_recording(o, dir_->path());
    ASSERT_TRUE(s) << s.error().message;
  }
  static void TearDownTestSuite() {
    delete dir_;
    dir_ = nullptr;
  }
  static test::TempDir* dir_;
};
test::TempDir* DiscoverSim::dir_ = nullptr;

TEST_F(DiscoverSim, FindsBodiesJointsAndParametersOfTheTruth) {
  auto points = discover::triangulate_recording(dir_->path());
  ASSERT_TRUE(points) << points.error().message;
  discover::DiscoverOptions opt;
  auto r = discover::discover_model(*points, opt, dir_->path());
  ASSERT_TRUE(r) << r.error().message;
  for (const auto& w : r->warnings) std::printf("warning: %s\n", w.c_str());
  auto truth = test::compare_with_truth(dir_->path(), *r);
  ASSERT_TRUE(truth) << truth.error().message;
  SCOPED_TRACE(truth->describe());
  EXPECT_EQ(r->targets.bodies.size(), 3U);
  EXPECT_EQ(truth->bodies_complete, truth->true_bodies);
  EXPECT_EQ(truth->wrong_markers, 0);
  EXPECT_EQ(truth->unmatched_markers, 0);
  EXPECT_TRUE(truth->topology_ok);
  EXPECT_LT(truth->worst_ball_center_mm, 0.5);
  EXPECT_LT(truth->worst_hinge_axis_deg, 0.3);
  EXPECT_LT(truth->worst_hinge_line_mm, 0.5);
  // The root is the still torso: the body with the smallest world motion comes first.
  ASSERT_FALSE(r->model.joints.empty());
  EXPECT_EQ(r->model.joints.front().parent, "body0");
}

// The short-term tracker never jumps to a neighbour: every point of a track lies on the
// same true marker (gt/markers.csv, within 2 mm) all along the track.
TEST_F(DiscoverSim, TracksStayOnOneMarker) {
  auto points = discover::triangulate_recording(dir_->path());
  ASSERT_TRUE(points) << points.error().message;
  auto gt = read_gt_markers_csv(dir_->path() + "/gt/markers.csv");
  ASSERT_TRUE(gt) << gt.error().message;
  std::map<std::int64_t, std::vector<const GtMarker*>> by_frame;
  for (const GtMarker& m : *gt) by_frame[m.frame].push_back(&m);
  discover::DiscoverOptions opt;
  const auto tracks = discover::track_points(*points, opt);
  int long_tracks = 0, switches = 0, labelled = 0;
  for (const auto& t : tracks) {
    if (t.seen < opt.min_track_frames) continue;
    ++long_tracks;
    std::string label;
    for (int f = t.first; f <= t.last(); ++f) {
      if (!t.has(f)) continue;
      for (const GtMarker* m : by_frame[points->frames[static_cast<std::size_t>(f)].frame]) {
        if ((m->X_world - t.at(f)).norm() > 2.0) continue;
        const std::string l = m->body + "/" + std::to_string(m->marker);
        ++labelled;
        if (!label.empty() && l != label) ++switches;
        label = l;
      }
    }
  }
  EXPECT_GE(long_tracks, 10);  // 14 markers, most seen for long stretches
  EXPECT_GT(labelled, 1000);
  EXPECT_EQ(switches, 0);
}

// Fewer frames than needed, and no motion at all: one-line errors naming the recording.
TEST(DiscoverErrors, TooFewFramesAndStaticScene) {
  discover::PointSequence seq;
  for (int f = 0; f < 10; ++f)
    seq.frames.push_back({f, f * 10000000LL, {Vec3(0, 0, 0), Vec3(50, 0, 0), Vec3(0, 60, 0)}});
  discover::DiscoverOptions opt;
  auto r = discover::discover_model(seq, opt, "rec");
  ASSERT_FALSE(r);
  EXPECT_EQ(r.error().message, "rec: 10 frames, at least 30 are needed to discover bodies and joints");
  for (int f = 10; f < 60; ++f)
    seq.frames.push_back({f, f * 10000000LL, {Vec3(0, 0, 0), Vec3(50, 0, 0), Vec3(0, 60, 0)}});
  r = discover::discover_model(seq, opt, "rec");
  ASSERT_FALSE(r);
  EXPECT_NE(r.error().message.find("rec: nothing moves (a static scene)"), std::string::npos) << r.error().message;
}

}  // namespace
}  // namespace mocap
