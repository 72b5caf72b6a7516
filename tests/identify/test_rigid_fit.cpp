// Design: tests of the unweighted rigid fit (identify/rigid_fit.h): Horn's quaternion
// solved as in QCP against Eigen::umeyama (the former fit) on random correspondences of
// the search's sizes (3..16 columns), at marker noise and far beyond it (where the
// reflection fix matters), half turns, nearly collinear and coincident points (the
// fallback); the same residuals and decisions to ~1e-9, the same pose to 1e-6 mm.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "identify/rigid_fit.h"
#include "tests/identify/identify_test_util.h"

namespace mocap {
namespace {

void expect_same_fit(const FitPoints& src, const FitPoints& dst, int m) {
  const RigidFit ref = fit_rigid_umeyama(src, dst, m);
  const RigidFit fit = fit_rigid(src, dst, m);
  const double scale = 1.0 + ref.sum_sq_mm2;
  EXPECT_NEAR(fit.sum_sq_mm2, ref.sum_sq_mm2, 1e-9 * scale);
  EXPECT_NEAR(fit.max_sq_mm2, ref.max_sq_mm2, 1e-9 * scale);
  EXPECT_NEAR(fit.T_dst_src.linear().determinant(), 1.0, 1e-12);
  // The pose itself: where it moves every fitted point, to a millionth of a millimetre (with
  // 50 mm residuals the two eigen-solvers' own rounding differs by up to ~1e-7 mm).
  for (int i = 0; i < m; ++i)
    EXPECT_LT((fit.T_dst_src * Vec3(src.col(i)) - ref.T_dst_src * Vec3(src.col(i))).norm(), 1e-6);
}

TEST(RigidFit, QuaternionFitEqualsUmeyama) {
  std::mt19937_64 rng(31);
  std::normal_distribution<double> g(0.0, 1.0);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  for (int trial = 0; trial < 20000; ++trial) {
    const int m = 3 + trial % 14;
    Iso3 T = Iso3::Identity();
    T.linear() = test::random_rotation(rng);
    T.translation() = Vec3(g(rng), g(rng), g(rng)) * 1000.0;
    // From marker noise to residuals larger than the target (a bad correspondence).
    const double noise = trial % 4 == 3 ? 50.0 : 0.2 * u(rng);
    FitPoints src(3, kMaxMarkers), dst(3, kMaxMarkers);
    for (int i = 0; i < m; ++i) {
      src.col(i) = Vec3(g(rng), g(rng), g(rng)) * 60.0;
      dst.col(i) = T * Vec3(src.col(i)) + Vec3(g(rng), g(rng), g(rng)) * noise;
    }
    expect_same_fit(src, dst, m);
  }
}

TEST(RigidFit, HalfTurnsMirrorsAndDegenerateInputs) {
  std::mt19937_64 rng(32);
  std::normal_distribution<double> g(0.0, 1.0);
  for (int trial = 0; trial < 2000; ++trial) {
    const int m = 3 + trial % 5;
    const Vec3 axis = Vec3(g(rng), g(rng), g(rng)).normalized();
    Iso3 T = Iso3::Identity();
    T.linear() = Eigen::AngleAxisd(M_PI - 1e-9 * (trial % 3), axis).toRotationMatrix();
    T.translation() = Vec3(0.0, 0.0, 1500.0);
    FitPoints src(3, kMaxMarkers), dst(3, kMaxMarkers);
    for (int i = 0; i < m; ++i) {
      src.col(i) = Vec3(g(rng), g(rng), g(rng)) * 60.0;
      Vec3 x = Vec3(src.col(i));
      if (trial % 5 == 1) x.z() = -x.z();                      // a mirror image: no rotation fits
      if (trial % 5 == 2) x = Vec3(x.x(), 1e-7 * x.y(), 0.0);  // nearly collinear
      if (trial % 5 == 3) x = Vec3(src.col(0));                // all on one point
      if (trial % 5 == 3 || trial % 5 == 2) src.col(i) = x;
      dst.col(i) = T * x;
    }
    SCOPED_TRACE("trial " + std::to_string(trial) + " kind " + std::to_string(trial % 5));
    expect_same_fit(src, dst, m);
  }
}

}  // namespace
}  // namespace mocap
