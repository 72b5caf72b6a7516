// SmallCholesky (core/small_cholesky.h): on random symmetric positive definite matrices
// of sizes 1..6 (conditioned up to 1e8) the solve and the inverse round-trip to the
// right-hand side and the identity, and agree with Eigen's LLT; an indefinite, a
// singular or a non-finite matrix is refused.
#include <gtest/gtest.h>

#include <Eigen/Cholesky>
#include <limits>
#include <random>

#include "core/small_cholesky.h"

namespace mocap {
namespace {

template <int N>
void round_trip(std::mt19937& rng) {
  using M = Eigen::Matrix<double, N, N>;
  using V = Eigen::Matrix<double, N, 1>;
  std::normal_distribution<double> g(0.0, 1.0);
  std::uniform_real_distribution<double> e(0.0, 8.0);
  for (int trial = 0; trial < 200; ++trial) {
    M A;
    for (int i = 0; i < N; ++i)
      for (int j = 0; j < N; ++j) A(i, j) = g(rng);
    const Eigen::HouseholderQR<M> qr(A);
    const M Q = qr.householderQ();
    V d;
    for (int i = 0; i < N; ++i) d[i] = std::pow(10.0, e(rng));
    const M H = Q * d.asDiagonal() * Q.transpose();
    V b;
    for (int i = 0; i < N; ++i) b[i] = g(rng);
    SmallCholesky<N> chol;
    ASSERT_TRUE(chol.compute(H)) << "trial " << trial;
    const V x = chol.solve(b);
    const double cond = d.maxCoeff() / d.minCoeff();
    // Backward stable: the residual is of the order of eps * cond * |b|.
    EXPECT_LT((H * x - b).norm(), 1e-13 * cond * b.norm()) << "trial " << trial;
    const V x_ref = H.llt().solve(b);
    EXPECT_LT((x - x_ref).norm(), 1e-8 * x_ref.norm()) << "trial " << trial;
    const M I = H * chol.inverse();
    EXPECT_LT((I - M::Identity()).norm(), 1e-15 * cond * 100) << "trial " << trial;
    const M inv = chol.inverse();
    EXPECT_LT((inv - inv.transpose()).norm(), 1e-12 * inv.norm());
  }
}

TEST(SmallCholesky, RoundTripsRandomPositiveDefiniteMatrices) {
  std::mt19937 rng(7);
  round_trip<1>(rng);
  round_trip<2>(rng);
  round_trip<3>(rng);
  round_trip<6>(rng);
}

TEST(SmallCholesky, RefusesIndefiniteSingularAndNonFinite) {
  SmallCholesky<3> chol;
  Mat3 H = Mat3::Identity();
  H(2, 2) = -1.0;
  EXPECT_FALSE(chol.compute(H));
  EXPECT_FALSE(chol.ok());
  const Vec3 v(1.0, 2.0, 3.0);
  EXPECT_FALSE(chol.compute(v * v.transpose()));  // rank 1
  H = Mat3::Identity();
  H(1, 1) = std::numeric_limits<double>::quiet_NaN();
  EXPECT_FALSE(chol.compute(H));
  H = Mat3::Identity();
  H(1, 0) = std::numeric_limits<double>::infinity();
  EXPECT_FALSE(chol.compute(H));
  EXPECT_TRUE(chol.compute(Mat3::Identity() * 4.0));
  EXPECT_TRUE(chol.ok());
  EXPECT_NEAR(chol.solve(v)[2], 0.75, 1e-15);
}

}  // namespace
}  // namespace mocap
