// Design: the essential-matrix relative pose: exact recovery from noise-free points,
// accuracy with pixel noise and 20% outliers, and the degenerate inputs.
#include <gtest/gtest.h>

#include <random>

#include "core/rotation.h"
#include "rigcal/essential.h"

namespace mocap::rigcal {
namespace {

struct Pair {
  std::vector<Vec2> x0, x1;
};

Pair make_points(const Mat3& R, const Vec3& t, int n, double noise, double outliers,
                 std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::normal_distribution<double> g(0.0, noise);
  Pair p;
  for (int i = 0; i < n; ++i) {
    const Vec3 X(400.0 * u(rng), 300.0 * u(rng), 1250.0 + 300.0 * u(rng));
    const Vec3 X1 = R * X + t;
    Vec2 a = X.hnormalized() + Vec2(g(rng), g(rng));
    Vec2 b = X1.hnormalized() + Vec2(g(rng), g(rng));
    if (i < static_cast<int>(outliers * n)) b = Vec2(0.3 * u(rng), 0.3 * u(rng));
    p.x0.push_back(a);
    p.x1.push_back(b);
  }
  return p;
}

TEST(Essential, RecoversPoseFromExactPoints) {
  const Mat3 R = rot_y(-0.38) * rot_x(0.02) * rot_z(-0.012);
  const Vec3 t(-470.0, 10.0, 80.0);
  const Pair p = make_points(R, t, 60, 0.0, 0.0, 3);
  EssentialOptions o;
  o.threshold = 1e-6;
  auto rel = estimate_relative_pose(p.x0, p.x1, o);
  ASSERT_TRUE(rel) << rel.error().message;
  EXPECT_LT((rel->R_1_0 - R).norm(), 1e-8);
  EXPECT_LT((rel->t_1_0 - t.normalized()).norm(), 1e-8);
  EXPECT_EQ(rel->inlier_count, 60);
}

TEST(Essential, RobustToNoiseAndOutliers) {
  const Mat3 R = rot_y(0.35) * rot_z(0.01);
  const Vec3 t(475.0, -5.0, 60.0);
  const Pair p = make_points(R, t, 600, 0.05 / 1290.0, 0.2, 5);
  EssentialOptions o;
  o.threshold = 1.5 / 1290.0;
  auto rel = estimate_relative_pose(p.x0, p.x1, o);
  ASSERT_TRUE(rel) << rel.error().message;
  EXPECT_LT(Eigen::AngleAxisd(rel->R_1_0 * R.transpose()).angle(), 2e-4);
  EXPECT_LT(std::acos(std::min(1.0, rel->t_1_0.dot(t.normalized()))), 2e-3);
  EXPECT_GE(rel->inlier_count, 470);
  EXPECT_LE(rel->inlier_count, 490);  // outliers rejected (a few fall near by chance)
}

TEST(Essential, Errors) {
  std::vector<Vec2> a(5, Vec2::Zero()), b(5, Vec2::Zero());
  auto r = estimate_relative_pose(a, b, EssentialOptions{});
  ASSERT_FALSE(r);
  EXPECT_NE(r.error().message.find("at least 8"), std::string::npos);
  std::vector<Vec2> c(20, Vec2(0.1, 0.1)), d(20, Vec2(0.2, 0.1));  // all identical: degenerate
  EXPECT_FALSE(estimate_relative_pose(c, d, EssentialOptions{}));
}

}  // namespace
}  // namespace mocap::rigcal
