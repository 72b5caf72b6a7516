// Tests for core/mat3_product.h: the written-out products are Eigen's, bit for bit, over
// random matrices and vectors of every scale (a different summation order would differ
// in the last bit in about a quarter of the cases).
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "core/mat3_product.h"

namespace mocap {
namespace {

TEST(Mat3Product, BitIdenticalToEigen) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::uniform_int_distribution<int> e(-8, 8);
  for (int trial = 0; trial < 200000; ++trial) {
    Mat3 M;
    const double sm = std::ldexp(1.0, 2 * e(rng)), sv = std::ldexp(1.0, 2 * e(rng));
    for (int k = 0; k < 9; ++k) M(k) = sm * u(rng);
    const Vec3 v(sv * u(rng), sv * u(rng), trial % 2 == 0 ? 1.0 : sv * u(rng));
    const Vec3 a = M * v;
    const Vec3 b = M.transpose() * v;
    const Vec3 ma = mul(M, v);
    const Vec3 mb = mul_transposed(M, v);
    for (int i = 0; i < 3; ++i) {
      ASSERT_EQ(ma(i), a(i)) << "trial " << trial << " row " << i;
      ASSERT_EQ(mb(i), b(i)) << "trial " << trial << " row " << i;
    }
  }
}

}  // namespace
}  // namespace mocap
