// Design: the Cholesky factorisation H = L L^T of a small fixed-size symmetric positive
// definite matrix (the 6x6 normal equations of a pose fit), unrolled by the compiler
// over N: Eigen's LLT runs its general blocked path for these sizes, at about ten times
// the instructions. Reads the lower triangle; compute() is false when a pivot is not
// positive and finite (the matrix is not positive definite to rounding), and the object
// then holds no factor. noexcept, no allocation.
#pragma once

#include <cmath>

#include "core/types.h"

namespace mocap {

template <int N>
class SmallCholesky {
 public:
  using Matrix = Eigen::Matrix<double, N, N>;
  using Vector = Eigen::Matrix<double, N, 1>;

  bool compute(const Matrix& H) noexcept {
    ok_ = false;
    for (int j = 0; j < N; ++j) {
      double d = H(j, j);
      for (int k = 0; k < j; ++k) d -= L_(j, k) * L_(j, k);
      if (!(d > 0.0) || !std::isfinite(d)) return false;
      const double l = std::sqrt(d);
      L_(j, j) = l;
      inv_diag_[j] = 1.0 / l;
      for (int i = j + 1; i < N; ++i) {
        double s = H(i, j);
        for (int k = 0; k < j; ++k) s -= L_(i, k) * L_(j, k);
        L_(i, j) = s * inv_diag_[j];
      }
    }
    ok_ = true;
    return true;
  }
  bool ok() const noexcept { return ok_; }

  // x = H^-1 b (after a successful compute()).
  Vector solve(const Vector& b) const noexcept {
    Vector y;
    for (int i = 0; i < N; ++i) {
      double s = b[i];
      for (int k = 0; k < i; ++k) s -= L_(i, k) * y[k];
      y[i] = s * inv_diag_[i];
    }
    Vector x;
    for (int i = N - 1; i >= 0; --i) {
      double s = y[i];
      for (int k = i + 1; k < N; ++k) s -= L_(k, i) * x[k];
      x[i] = s * inv_diag_[i];
    }
    return x;
  }

  // H^-1, symmetric (after a successful compute()).
  Matrix inverse() const noexcept {
    Matrix inv;
    for (int c = 0; c < N; ++c) inv.col(c) = solve(Vector::Unit(c));
    return inv;
  }

 private:
  Matrix L_ = Matrix::Zero();
  Vector inv_diag_ = Vector::Zero();
  bool ok_ = false;
};

}  // namespace mocap
