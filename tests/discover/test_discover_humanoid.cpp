// The whole robot: `mocap discover` on a short exploration recording of the simulator's
// humanoid (15 bodies, 14 joints, 71 markers), against the simulator's truth: every body
// with all but at most one of its markers, no marker in a wrong body, the 14 joints with
// their types in the right tree, ball centres and hinge lines within 0.5 mm (in world
// terms, discover_truth.h). Kept lean for CI (2 cores, ASan): 6 of the ring's cameras and
// 120 frames instead of the 8 x 300 of docs/discover.md (whose figures come from
// discover_eval on full-size recordings).
#include <gtest/gtest.h>

#include "discover/frame_points.h"
#include "discover_truth.h"
#include "tests/support/test_support.h"

namespace mocap {
namespace {

TEST(DiscoverHumanoid, WholeRobotFromAnExplorationRecording) {
  test::TempDir dir("discover_humanoid");
  const std::string rec = dir.file("rec");
  auto sim = test::run_mocap(
      "simulate --scene humanoid --motion explore --cameras 6 --frames 120 "
      "--seed 3 --out " +
          rec,
      900);
  ASSERT_EQ(sim.exit_code, 0) << sim.output;
  auto points = discover::triangulate_recording(rec);
  ASSERT_TRUE(points) << points.error().message;
  auto r = discover::discover_model(*points, discover::DiscoverOptions{}, rec,
                                    discover::tracker_poses(rec));
  ASSERT_TRUE(r) << r.error().message;
  auto truth = test::compare_with_truth(rec, *r);
  ASSERT_TRUE(truth) << truth.error().message;
  std::string detail = truth->describe();
  for (const std::string& l : truth->body_lines) detail += "\n  " + l;
  for (const std::string& l : truth->joint_lines) detail += "\n  " + l;
  SCOPED_TRACE(detail);
  EXPECT_EQ(r->targets.bodies.size(), 15U);
  EXPECT_EQ(truth->bodies_complete, 15);
  EXPECT_EQ(truth->wrong_markers, 0);
  EXPECT_EQ(truth->unmatched_markers, 0);
  EXPECT_EQ(truth->joints_right, 14);
  EXPECT_EQ(truth->joints_wrong, 0);
  EXPECT_TRUE(truth->topology_ok);
  EXPECT_LT(truth->worst_centre_mm(), 0.5);
  EXPECT_LT(truth->worst_hinge_axis_deg, 0.3);
  ASSERT_FALSE(r->model.joints.empty());
  EXPECT_EQ(r->model.joints.front().parent, "body0");  // the root: the pelvis (moves least)
  EXPECT_EQ(truth->body_map[0], 0);                    // gt body 0 is the pelvis
}

}  // namespace
}  // namespace mocap
