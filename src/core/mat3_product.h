// Design: 3x3 matrix times 3-vector products written out, for hot loops where Eigen
// evaluated `M * v` into a temporary through an out-of-line call (the N-view merge's and
// the stereo pairs' projections and epipolar lines). Each is bit for bit the Eigen
// expression it replaces, so a switch changes no result: the same products summed in the
// same order as Eigen's fixed-size kernels (SSE2, no FMA contraction at -O2 on x86-64):
//   M * v:              rows 0 and 1 from the left, ((a + b) + c); row 2 a + (b + c);
//   M.transpose() * v:  every row from the left, ((a + b) + c).
// tests/core/test_mat3_product.cpp compares both with Eigen over random inputs of every
// scale; it fails if an Eigen version sums differently. noexcept, inline, no allocation.
#pragma once

#include "core/types.h"

namespace mocap {

// == M * v (Eigen's result, bit for bit).
inline Vec3 mul(const Mat3& M, const Vec3& v) noexcept {
  const double x = v.x(), y = v.y(), z = v.z();
  return Vec3(M(0, 0) * x + M(0, 1) * y + M(0, 2) * z, M(1, 0) * x + M(1, 1) * y + M(1, 2) * z,
              M(2, 0) * x + (M(2, 1) * y + M(2, 2) * z));
}

// == M.transpose() * v (Eigen's result, bit for bit).
inline Vec3 mul_transposed(const Mat3& M, const Vec3& v) noexcept {
  const double x = v.x(), y = v.y(), z = v.z();
  return Vec3(M(0, 0) * x + M(1, 0) * y + M(2, 0) * z, M(0, 1) * x + M(1, 1) * y + M(2, 1) * z,
              M(0, 2) * x + M(1, 2) * y + M(2, 2) * z);
}

}  // namespace mocap
