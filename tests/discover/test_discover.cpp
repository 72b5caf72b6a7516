// Discover on a short simulated recording (smooth motion of the shoulder rig, no
// targets given), against the simulator's truth, in one test so the recording is
// rendered once:
//  - the short-term tracks never jump from one true marker to another;
//  - every body with all but at most one of its markers, no marker in a wrong body,
//    the topology and joint types, ball centres within 0.5 mm and hinge axes within
//    0.3 deg in world terms (discover_truth.h), with and without the tracker's poses;
//  - on a 4-camera rig, every camera takes part (frames without camera 1 still give points).
// The command line and the angles of `mocap run` with the result: test_walkthrough.cpp.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <map>

#include "discover/frame_points.h"
#include "discover/point_tracker.h"
#include "discover_truth.h"
#include "formats/csv_outputs.h"
#include "formats/recording.h"
#include "tests/support/test_support.h"
#include "track/truth.h"

namespace mocap {
namespace {

using test::run_mocap;

void expect_tracks_stay_on_one_marker(const std::string& rec,
                                      const discover::PointSequence& points) {
  auto gt = read_gt_markers_csv(rec + "/gt/markers.csv");
  ASSERT_TRUE(gt) << gt.error().message;
  std::map<std::int64_t, std::vector<const GtMarker*>> by_frame;
  for (const GtMarker& m : *gt) by_frame[m.frame].push_back(&m);
  discover::DiscoverOptions opt;
  const auto tracked = discover::point_tracks(points, opt);  // still fragments stitched
  const auto& tracks = tracked.tracks;
  EXPECT_GT(tracked.point_noise_mm, 0.005);  // estimated from the tracks
  EXPECT_LT(tracked.point_noise_mm, 0.1);
  int long_tracks = 0, switches = 0, labelled = 0;
  for (const auto& t : tracks) {
    if (t.seen < opt.min_track_frames) continue;
    ++long_tracks;
    std::string label;
    for (int f = t.first; f <= t.last(); ++f) {
      if (!t.has(f)) continue;
      for (const GtMarker* m : by_frame[points.frames[static_cast<std::size_t>(f)].frame]) {
        if ((m->X_world - t.at(f)).norm() > 2.0) continue;
        const std::string l = m->body + "/" + std::to_string(m->marker);
        ++labelled;
        if (!label.empty() && l != label) ++switches;
        label = l;
      }
    }
  }
  EXPECT_GE(long_tracks, 10);  // 16 markers, most seen for long stretches
  EXPECT_GT(labelled, 1000);
  EXPECT_EQ(switches, 0);
}

TEST(DiscoverSim, SimulatedRecordingAgainstTruth) {
  test::TempDir dir("discover_sim");
  const std::string rec = dir.file("rec");
  // The default `limbs` scene: the arm hides the torso's balls and its own in turn, so
  // most markers are seen in fragments of 10-60 frames.
  auto sim = run_mocap("simulate --out " + rec + " --frames 150 --seed 7", 300);
  ASSERT_EQ(sim.exit_code, 0) << sim.output;

  auto points = discover::triangulate_recording(rec);
  ASSERT_TRUE(points) << points.error().message;
  expect_tracks_stay_on_one_marker(rec, *points);

  // Targets from the tracks alone must already be right; the joints are then estimated
  // on the tracker's poses of those targets (as `mocap discover` does).
  auto bare = discover::discover_model(*points, discover::DiscoverOptions{}, rec);
  ASSERT_TRUE(bare) << bare.error().message;
  auto r = discover::discover_model(*points, discover::DiscoverOptions{}, rec,
                                    discover::tracker_poses(rec));
  ASSERT_TRUE(r) << r.error().message;
  ASSERT_EQ(bare->targets.bodies.size(), r->targets.bodies.size());
  for (std::size_t b = 0; b < r->targets.bodies.size(); ++b)
    EXPECT_EQ(bare->targets.bodies[b].markers_body.size(),
              r->targets.bodies[b].markers_body.size());
  EXPECT_GT(r->stats.point_noise_mm, 0.005);
  EXPECT_LT(r->stats.point_noise_mm, 0.1);
  auto truth = test::compare_with_truth(rec, *r);
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
  ASSERT_FALSE(r->model.joints.empty());
  EXPECT_EQ(r->model.joints.front().parent, "body0");  // the root: the still torso

  // The command line, `mocap run` with the result and the angles against the truth:
  // test_walkthrough.cpp.
}

// A 4-camera rig: every camera takes part, not only the pair (0, 1). Camera 1's images
// are removed from every other frame: those frames still give points from cameras 0, 2
// and 3 (a stereo pair (0, 1) would give none), and every point lies on a true marker.
// A few frames only (CI has 2 cores).
TEST(DiscoverSim, FourCameraRecordingUsesEveryCamera) {
  test::TempDir dir("discover_4cam");
  const std::string rec = dir.file("rec");
  constexpr int kFrames = 8;
  auto sim = run_mocap(
      "simulate --cameras 4 --frames " + std::to_string(kFrames) + " --seed 3 --out " + rec, 300);
  ASSERT_EQ(sim.exit_code, 0) << sim.output;
  for (int f = 0; f < kFrames; f += 2)
    ASSERT_TRUE(std::filesystem::remove(frame_file_path(rec, "cam1", f)));

  auto points = discover::triangulate_recording(rec);
  ASSERT_TRUE(points) << points.error().message;
  ASSERT_EQ(points->frames.size(), static_cast<std::size_t>(kFrames));
  EXPECT_EQ(points->frames_missing_camera, kFrames / 2);
  auto gt = read_gt_markers_csv(rec + "/gt/markers.csv");
  ASSERT_TRUE(gt) << gt.error().message;
  int without_cam1 = 0, off_marker = 0;
  for (const discover::FramePoints& fp : points->frames) {
    for (const Vec3& X : fp.X_world_mm) {
      double nearest = 1e9;
      for (const GtMarker& m : *gt)
        if (m.frame == fp.frame) nearest = std::min(nearest, (m.X_world - X).norm());
      off_marker += nearest > 1.0 ? 1 : 0;
    }
    if (fp.frame % 2 == 0) without_cam1 += static_cast<int>(fp.X_world_mm.size());
  }
  // Only trusted points are kept (no ambiguous candidate, no view from a flagged blob):
  // on this arc a few per frame; a pair (0, 1) alone would give none at all.
  EXPECT_GE(without_cam1, kFrames / 2);
  EXPECT_EQ(off_marker, 0);
}

// Fewer frames than needed, and no motion at all: one-line errors naming the recording.
TEST(DiscoverErrors, TooFewFramesAndStaticScene) {
  discover::PointSequence seq;
  for (int f = 0; f < 10; ++f)
    seq.frames.push_back({f, f * 10000000LL, {Vec3(0, 0, 0), Vec3(50, 0, 0), Vec3(0, 60, 0)}});
  discover::DiscoverOptions opt;
  auto r = discover::discover_model(seq, opt, "rec");
  ASSERT_FALSE(r);
  EXPECT_EQ(r.error().message,
            "rec: 10 frames, at least 30 are needed to discover bodies and joints");
  for (int f = 10; f < 60; ++f)
    seq.frames.push_back({f, f * 10000000LL, {Vec3(0, 0, 0), Vec3(50, 0, 0), Vec3(0, 60, 0)}});
  r = discover::discover_model(seq, opt, "rec");
  ASSERT_FALSE(r);
  EXPECT_NE(r.error().message.find("rec: nothing moves (a static scene)"), std::string::npos)
      << r.error().message;
}

// The whole robot turned rigidly (joints fixed): one body, no joint to find.
TEST(DiscoverErrors, OneRigidBodyOnly) {
  const std::vector<Vec3> markers = {Vec3(0, 0, 0), Vec3(60, 0, 0), Vec3(0, 45, 0),
                                     Vec3(20, 30, 40), Vec3(-35, 10, 25)};
  discover::PointSequence seq;
  for (int f = 0; f < 120; ++f) {  // 1.2 s at 100 Hz, turning 90 deg about a tilted axis
    const Iso3 T =
        make_iso(Eigen::AngleAxisd(0.0131 * f, Vec3(0.3, 1.0, 0.2).normalized()).toRotationMatrix(),
                 Vec3(100.0 + 0.5 * f, -50.0, 1000.0));
    std::vector<Vec3> pts;
    for (const Vec3& m : markers) pts.push_back(T * m);
    seq.frames.push_back({f, f * 10000000LL, pts});
  }
  auto r = discover::discover_model(seq, discover::DiscoverOptions{}, "rec");
  ASSERT_FALSE(r);
  EXPECT_EQ(r.error().message.rfind("rec: one rigid body only (5 markers", 0), 0u)
      << r.error().message;
}

}  // namespace
}  // namespace mocap
