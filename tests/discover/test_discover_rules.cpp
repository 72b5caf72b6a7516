// Unit tests of two rules of `mocap discover` (docs/discover.md):
//  - the frame counts and turns of the rigidity tests are derived from the noise
//    (discover_types.h): they grow as the noise approaches the bound, a rigid pair that
//    turns by the derived amount is rigid, one that turns by much less is not decided,
//    and a pair on two bodies moving that much apart is non-rigid;
//  - one body built as two (body_union.h): two children of one parent at one joint
//    centre with a constant relative pose are merged into one body with both bodies'
//    markers; children at one centre that move independently are not.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>

#include "discover/body_union.h"
#include "discover/rigid_groups.h"
#include "discover/topology.h"

namespace mocap {
namespace {

using discover::DiscoveredBody;
using discover::DiscoverOptions;

DiscoverOptions options_with_noise(double sigma_mm) {
  DiscoverOptions opt;
  opt.point_noise_mm = sigma_mm;
  return opt;
}

TEST(DiscoverThresholds, FrameCountsFollowTheNoise) {
  // Far below the bound: the floor of the robust statistics.
  EXPECT_EQ(DiscoverOptions::frames_for(0.01, 1.0), DiscoverOptions::kMinSamples);
  // The count grows as the noise approaches the bound, (3 * 1.17 s / (b - s))^2.
  EXPECT_EQ(DiscoverOptions::frames_for(0.5, 1.0), static_cast<int>(std::ceil(3.51 * 3.51)));
  EXPECT_LT(DiscoverOptions::frames_for(0.5, 1.0), DiscoverOptions::frames_for(0.7, 1.0));
  EXPECT_GT(DiscoverOptions::frames_for(1.0, 1.0), 100000);  // a bound that cannot be met
  // With the estimated noise of our recordings (0.015-0.1 mm) 5 frames decide; a noise
  // near the placement tolerance's own scale needs more.
  EXPECT_EQ(options_with_noise(0.017).min_covisible_frames(), 5);
  EXPECT_EQ(options_with_noise(0.017).min_placement_frames(), 5);
  DiscoverOptions noisy = options_with_noise(1.0);
  noisy.model_error_mm = 0.0;
  EXPECT_GT(noisy.min_placement_frames(), 5);
  // The turn: 10 b / length (pairs), sqrt(12) tol / lever (bodies).
  const DiscoverOptions opt = options_with_noise(0.02);
  EXPECT_NEAR(opt.min_pair_turn_rad(100.0), 10.0 * opt.pair_distance_std_mm() / 100.0, 1e-12);
  EXPECT_NEAR(opt.min_body_turn_rad(50.0), std::sqrt(12.0) * opt.body_fit_tolerance_mm() / 50.0,
              1e-12);
  EXPECT_GT(opt.min_pair_turn_rad(40.0), opt.min_pair_turn_rad(100.0));
}

// Two points `length` apart turning by `turn_rad` over `frames` frames about a vertical
// axis through the first; `drift_mm` moves the second along the pair (a second body).
std::pair<discover::PointTrack, discover::PointTrack> turning_pair(double length, double turn_rad,
                                                                   int frames, double drift_mm) {
  discover::PointTrack a, b;
  for (int f = 0; f < frames; ++f) {
    const double s = static_cast<double>(f) / (frames - 1);
    const double ang = turn_rad * s;
    const Vec3 dir(std::cos(ang), std::sin(ang), 0.0);
    const Vec3 A(100.0 + 30.0 * s, 0.0, 1000.0);
    a.X_world_mm.push_back(A);
    b.X_world_mm.push_back(A + (length + drift_mm * (s - 0.5)) * dir);
  }
  a.seen = b.seen = frames;
  return {a, b};
}

TEST(DiscoverThresholds, PairVerdictNeedsTheDerivedTurn) {
  const DiscoverOptions opt = options_with_noise(0.02);
  const double length = 80.0;
  const double turn = opt.min_pair_turn_rad(length);
  const int n = opt.min_covisible_frames() + 3;
  const std::vector<char> moving(static_cast<std::size_t>(n), 1);
  {
    const auto [a, b] = turning_pair(length, 1.5 * turn, n, 0.0);
    EXPECT_EQ(discover::classify_pair(a, b, moving, opt), discover::PairRelation::kRigid);
  }
  {
    const auto [a, b] = turning_pair(length, 0.3 * turn, n, 0.0);
    EXPECT_EQ(discover::classify_pair(a, b, moving, opt), discover::PairRelation::kUnknown);
  }
  {  // the distance sweeping length * turn, as a pair on two bodies turning that much apart
    const auto [a, b] = turning_pair(length, 1.5 * turn, n, 1.5 * turn * length);
    EXPECT_EQ(discover::classify_pair(a, b, moving, opt), discover::PairRelation::kNonRigid);
  }
  {  // too few frames for the statistics
    const auto [a, b] = turning_pair(length, 1.5 * turn, opt.min_covisible_frames() - 1, 0.0);
    EXPECT_NE(discover::classify_pair(a, b, moving, opt), discover::PairRelation::kRigid);
  }
}

// A body with the given markers, posed in every frame by `pose(f)`.
template <class Pose>
DiscoveredBody make_body(const std::vector<Vec3>& markers, int frames, Pose pose) {
  DiscoveredBody b;
  b.markers_body = markers;
  b.marker_tracks.assign(markers.size(), {});
  b.found.assign(static_cast<std::size_t>(frames), 1);
  for (int f = 0; f < frames; ++f) b.T_world_body.push_back(pose(f));
  return b;
}

Mat3 swing(int f, double phase) {  // three degrees of freedom, +-40 deg
  const double t = 0.01 * f;
  return (Eigen::AngleAxisd(0.7 * std::sin(2.1 * t + phase), Vec3::UnitX()) *
          Eigen::AngleAxisd(0.6 * std::sin(3.3 * t + 2.0 * phase), Vec3::UnitY()) *
          Eigen::AngleAxisd(0.5 * std::sin(1.7 * t + 0.5), Vec3::UnitZ()))
      .toRotationMatrix();
}

struct SplitScene {
  std::vector<DiscoveredBody> bodies;  // parent, child half A (4 markers), child half B (3)
};

// A parent swaying in the world and a child on a ball joint at `centre` (parent frame);
// the child is given as two bodies A and B: B's frame is fixed in A's (same motion) or,
// with `independent`, B swings on its own about the same centre.
SplitScene split_scene(bool independent) {
  constexpr int kFrames = 150;
  const Vec3 centre(0.0, 0.0, -120.0);
  auto T_parent = [](int f) {
    return make_iso(Eigen::AngleAxisd(0.2 * std::sin(0.03 * f), Vec3::UnitZ()).toRotationMatrix(),
                    Vec3(10.0 * std::sin(0.05 * f), 0.0, 1000.0));
  };
  auto child = [&](int f, double phase) {
    return T_parent(f) * Eigen::Translation3d(centre) * make_iso(swing(f, phase), Vec3::Zero()) *
           Eigen::Translation3d(Vec3(0.0, 0.0, -150.0));
  };
  const Iso3 T_ab =
      make_iso(Eigen::AngleAxisd(0.4, Vec3::UnitY()).toRotationMatrix(), Vec3(5.0, -20.0, 40.0));
  SplitScene s;
  s.bodies.push_back(make_body(
      {Vec3(60, 0, 0), Vec3(-50, 20, 0), Vec3(0, 70, 10), Vec3(0, -40, 60)}, kFrames, T_parent));
  s.bodies.push_back(
      make_body({Vec3(30, 0, 40), Vec3(-35, 10, -50), Vec3(0, 40, 0), Vec3(5, -30, 20)}, kFrames,
                [&](int f) { return child(f, 0.0); }));
  s.bodies.push_back(make_body({Vec3(40, 0, 0), Vec3(-30, 25, 10), Vec3(0, -45, 30)}, kFrames,
                               [&](int f) { return child(f, independent ? 1.9 : 0.0) * T_ab; }));
  return s;
}

TEST(DiscoverUnion, OneBodyBuiltAsTwoIsMerged) {
  const DiscoverOptions opt = options_with_noise(0.02);
  SplitScene s = split_scene(false);
  const auto topo = discover::infer_topology(s.bodies, opt);
  const auto pairs = discover::find_split_bodies(s.bodies, topo, opt);
  ASSERT_EQ(pairs.size(), 1U);
  EXPECT_EQ(pairs[0], std::make_pair(1, 2));  // the larger half keeps its place
  const auto merged = discover::merge_bodies(s.bodies, pairs, opt);
  ASSERT_EQ(merged.size(), 2U);
  EXPECT_EQ(merged[1].markers_body.size(), 7U);
  // Every marker of B is where the merged body says, in every frame.
  for (int f : {0, 77, 149}) {
    const std::size_t uf = static_cast<std::size_t>(f);
    for (const Vec3& m : s.bodies[2].markers_body) {
      const Vec3 X = s.bodies[2].T_world_body[uf] * m;
      double nearest = 1e9;
      for (const Vec3& k : merged[1].markers_body)
        nearest = std::min(nearest, (merged[1].T_world_body[uf] * k - X).norm());
      EXPECT_LT(nearest, 1e-6) << "frame " << f;
    }
  }
  // The merged body's frame keeps its origin at its markers' centroid.
  Vec3 c = Vec3::Zero();
  for (const Vec3& m : merged[1].markers_body) c += m;
  EXPECT_LT(c.norm(), 1e-9);
}

TEST(DiscoverUnion, ChildrenAtOneCentreMovingApartStayTwo) {
  const DiscoverOptions opt = options_with_noise(0.02);
  SplitScene s = split_scene(true);
  const auto topo = discover::infer_topology(s.bodies, opt);
  EXPECT_EQ(topo.joints.size(), 2U);  // both on ball joints to the parent
  EXPECT_TRUE(discover::find_split_bodies(s.bodies, topo, opt).empty());
  Iso3 T;
  EXPECT_FALSE(discover::constant_relative_pose(s.bodies[1], s.bodies[2], opt, T));
}

}  // namespace
}  // namespace mocap
