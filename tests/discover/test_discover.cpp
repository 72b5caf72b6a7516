// Discover on a short simulated recording (smooth motion of the shoulder rig, no
// targets given), against the simulator's truth, in one test so the recording is
// rendered once:
//  - the short-term tracks never jump from one true marker to another;
//  - every body with all but at most one of its markers, no marker in a wrong body,
//    the topology and joint types, ball centres within 0.5 mm and hinge axes within
//    0.3 deg in world terms (discover_truth.h);
//  - `mocap discover` + `mocap track --model` give the true joint angles: a hinge up to
//    a constant offset and sign (the discovered body frames differ from the true ones),
//    a ball joint through the frame-independent angle of R_rel(f) R_rel(f0)^T.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <map>

#include "discover/frame_points.h"
#include "discover/point_tracker.h"
#include "discover_truth.h"
#include "formats/csv_outputs.h"
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
  const auto tracks = discover::point_tracks(points, opt);  // still fragments stitched
  EXPECT_GT(opt.point_noise_mm, 0.005);                     // estimated from the tracks
  EXPECT_LT(opt.point_noise_mm, 0.1);
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

void expect_true_angles(const std::string& angles_csv, const std::string& truth_csv) {
  auto found = read_angles_csv(angles_csv);
  ASSERT_TRUE(found) << found.error().message;
  auto truth = read_angles_csv(truth_csv);
  ASSERT_TRUE(truth) << truth.error().message;
  std::map<std::pair<JointType, std::int64_t>, AngleRow> true_rows;
  for (const AngleRow& r : *truth) true_rows[{r.type, r.frame}] = r;
  std::vector<double> sum, diff;                // hinge: found +- true
  std::vector<std::pair<double, double>> ball;  // (found, true) angles from the first frame, deg
  const AngleRow* ball_f0 = nullptr;
  const AngleRow* ball_t0 = nullptr;
  for (const AngleRow& r : *found) {
    auto it = true_rows.find({r.type, r.frame});
    if (it == true_rows.end()) continue;
    const AngleRow& t = it->second;
    if (r.type == JointType::kHinge) {
      sum.push_back(r.angles_deg.x() + t.angles_deg.x());
      diff.push_back(r.angles_deg.x() - t.angles_deg.x());
      continue;
    }
    if (ball_f0 == nullptr) {
      ball_f0 = &r;
      ball_t0 = &t;
    }
    ball.emplace_back(
        r.q_parent_child.angularDistance(ball_f0->q_parent_child) * 57.29577951308232,
        t.q_parent_child.angularDistance(ball_t0->q_parent_child) * 57.29577951308232);
  }
  // The tracker finds this scene's lower arm in part of the frames only (also with the true
  // targets).
  ASSERT_GE(diff.size(), 30U);
  ASSERT_GE(ball.size(), 100U);
  // Deviations from the mean offset, sorted. With the discovered targets the lower arm
  // lacks its rarely seen fifth marker: in a few frames its pose comes through the chain
  // from 2 markers, one of them partly hidden (docs/discover.md), so the bound is on 97 %
  // of the frames, with every frame within 3 deg.
  auto deviations = [](const std::vector<double>& v) {
    double m = 0.0;
    for (double x : v) m += x;
    m /= static_cast<double>(v.size());
    std::vector<double> d;
    for (double x : v) d.push_back(std::abs(std::remainder(x - m, 360.0)));
    std::sort(d.begin(), d.end());
    return d;
  };
  auto p97 = [](const std::vector<double>& d) {
    return d[static_cast<std::size_t>(0.97 * static_cast<double>(d.size() - 1))];
  };
  const auto d_sum = deviations(sum), d_diff = deviations(diff);
  const auto& hinge = p97(d_sum) < p97(d_diff) ? d_sum : d_diff;  // the axis sign is free
  EXPECT_LT(p97(hinge), 0.5);
  EXPECT_LT(hinge.back(), 3.0);
  std::vector<double> d_ball;
  for (const auto& [a, b] : ball) d_ball.push_back(std::abs(a - b));
  std::sort(d_ball.begin(), d_ball.end());
  EXPECT_LT(p97(d_ball), 0.5);
  EXPECT_LT(d_ball.back(), 3.0);
}

TEST(DiscoverSim, SimulatedRecordingAgainstTruth) {
  test::TempDir dir("discover_sim");
  const std::string rec = dir.file("rec"), out = dir.file("found"), trk = dir.file("track");
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

  auto disc = run_mocap(
      "discover " + rec + " --out " + out + " --urdf " + out + "/robot.urdf --stats", 120);
  ASSERT_EQ(disc.exit_code, 0) << disc.output;
  EXPECT_NE(disc.output.find("discovered 3 bodies and 2 joints"), std::string::npos) << disc.output;
  EXPECT_NE(test::read_file(out + "/robot.urdf").find("<robot"), std::string::npos);
  auto track = run_mocap("track " + rec + " --targets " + out + "/targets.yaml --model " + out +
                             "/model.yaml --out " + trk,
                         120);
  ASSERT_EQ(track.exit_code, 0) << track.output;
  expect_true_angles(trk + "/angles.csv", rec + "/gt/angles.csv");
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

}  // namespace
}  // namespace mocap
