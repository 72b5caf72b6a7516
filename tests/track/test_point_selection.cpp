// Design: tests of the reported-point selection (track/point_selection.h) on hand-made
// candidate sets: two markers on one epipolar plane give two true candidates and two
// ghosts sharing their blobs; each evidence tier must pick one candidate per blob, in
// the order body > unambiguous > temporal continuity > epipolar fit; no allocation.
#include <gtest/gtest.h>

#include "tests/support/alloc_counter.h"
#include "track/point_selection.h"

namespace mocap {
namespace {

Point3 cand(const Vec3& X, int a, int b, double epi_px, bool ambiguous = true) {
  Point3 p;
  p.X_world = X;
  p.blob_index[0] = static_cast<std::int16_t>(a);
  p.blob_index[1] = static_cast<std::int16_t>(b);
  p.epipolar_px = epi_px;
  p.ambiguous = ambiguous;
  return p;
}

// True markers at A (blobs 0/0) and B (1/1); ghosts (0/1) and (1/0); plus an unrelated
// unambiguous marker C (2/2).
PointList crossing(double epi_true, double epi_ghost, const Vec3& shift = Vec3::Zero()) {
  PointList pts(8);
  pts.push_back(cand(Vec3(0, 0, 1000) + shift, 0, 0, epi_true));
  pts.push_back(cand(Vec3(40, 0, 1100) + shift, 0, 1, epi_ghost));
  pts.push_back(cand(Vec3(-35, 0, 900) + shift, 1, 0, epi_ghost));
  pts.push_back(cand(Vec3(50, 0, 1000) + shift, 1, 1, epi_true));
  pts.push_back(cand(Vec3(0, 80, 1000) + shift, 2, 2, 0.3, false));
  return pts;
}

int reported(const PointList& pts) {
  int n = 0;
  for (const Point3& p : pts) n += p.reported ? 1 : 0;
  return n;
}

TEST(PointSelection, MutualBestEpipolarFitWithoutOtherEvidence) {
  auto sel = PointSelector::create(8, 8, PointSelectionConfig{});
  ASSERT_TRUE(sel.ok());
  PointList pts = crossing(0.2, 0.6);
  const auto st = sel->select(BodyPoses{}, 0, pts);
  EXPECT_TRUE(pts[0].reported && pts[3].reported && pts[4].reported);
  EXPECT_FALSE(pts[1].reported || pts[2].reported);
  EXPECT_EQ(st.unambiguous, 1);
  EXPECT_EQ(st.by_epipolar, 2);
  EXPECT_EQ(st.rejected, 2);
}

TEST(PointSelection, TemporalContinuityBeatsABetterEpipolarFit) {
  auto sel = PointSelector::create(8, 8, PointSelectionConfig{});
  ASSERT_TRUE(sel.ok());
  PointList first = crossing(0.2, 0.6);
  sel->select(BodyPoses{}, 0, first);
  // 10 ms later the markers moved 2 mm and the ghosts happen to fit the lines better.
  PointList pts = crossing(0.7, 0.1, Vec3(2.0, 0.0, 0.0));
  const auto st = sel->select(BodyPoses{}, 10'000'000, pts);
  EXPECT_TRUE(pts[0].reported && pts[3].reported);
  EXPECT_FALSE(pts[1].reported || pts[2].reported);
  EXPECT_EQ(st.by_continuity, 2);
  // Too long a gap: no temporal evidence, the epipolar fit decides (the ghosts).
  PointList late = crossing(0.7, 0.1, Vec3(4.0, 0.0, 0.0));
  sel->select(BodyPoses{}, 1'000'000'000, late);
  EXPECT_TRUE(late[1].reported && late[2].reported);
  EXPECT_EQ(reported(late), 3);
}

TEST(PointSelection, IdentifiedBodyPointsWin) {
  auto sel = PointSelector::create(8, 8, PointSelectionConfig{});
  ASSERT_TRUE(sel.ok());
  PointList pts = crossing(0.2, 0.6);
  BodyPoses poses;
  poses.count = 1;
  poses.bodies[0].found = true;
  poses.bodies[0].point_index_of_marker.fill(-1);
  poses.bodies[0].point_index_of_marker[0] = 1;  // the body says (0/1) is its marker
  const auto st = sel->select(poses, 0, pts);
  EXPECT_EQ(st.by_body, 1);
  EXPECT_TRUE(pts[1].reported && pts[2].reported);  // (1/0) is the only one left for its blobs
  EXPECT_FALSE(pts[0].reported || pts[3].reported);
  EXPECT_EQ(reported(pts), 3);
}

TEST(PointSelection, ErrorsAndNoAllocation) {
  PointSelectionConfig bad;
  bad.point_sigma_mm = 0.0;
  auto e = PointSelector::create(8, 8, bad);
  ASSERT_FALSE(e.ok());
  EXPECT_NE(e.error().message.find("point_sigma_mm"), std::string::npos);
  EXPECT_FALSE(PointSelector::create(0, 8, PointSelectionConfig{}).ok());
  auto sel = PointSelector::create(8, 8, PointSelectionConfig{});
  ASSERT_TRUE(sel.ok());
  PointList pts = crossing(0.2, 0.6);
  PointList more = crossing(0.2, 0.6, Vec3(1, 0, 0));
  // A blob index beyond the capacity never reads out of bounds: not reported.
  more[4].blob_index[0] = 100;
  test::AllocationScope scope;
  sel->select(BodyPoses{}, 0, pts);
  sel->select(BodyPoses{}, 10'000'000, more);
  EXPECT_EQ(scope.count(), 0u);
  EXPECT_FALSE(more[4].reported);
}

}  // namespace
}  // namespace mocap
