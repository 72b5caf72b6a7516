// Design: least-squares rigid fit of m <= kMaxMarkers correspondences with
// Eigen::umeyama (no scaling), and its weighted form (weighted centroids and cross-
// covariance, Kabsch by a fixed-size 3x3 SVD with the reflection fixed) for fits that mix
// whole and partial markers of different noise. The point matrices have a fixed maximum
// size, so Eigen allocates nothing: usable in the hot path.
#pragma once

#include <Eigen/Geometry>
#include <Eigen/SVD>
#include <array>

#include "identify/identify_types.h"

namespace mocap {

using FitPoints = Eigen::Matrix<double, 3, Eigen::Dynamic, Eigen::ColMajor, 3, kMaxMarkers>;

struct RigidFit {
  Iso3 T_dst_src = Iso3::Identity();
  double sum_sq_mm2 = 0.0;  // sum of squared residuals |T*src - dst|^2
  double max_sq_mm2 = 0.0;  // largest squared residual
};

// Fits the first m columns (3 <= m <= kMaxMarkers). T_dst_src maps src into dst.
inline RigidFit fit_rigid(const FitPoints& src, const FitPoints& dst, int m) noexcept {
  RigidFit fit;
  fit.T_dst_src.matrix() = Eigen::umeyama(src.leftCols(m), dst.leftCols(m), false);
  for (Eigen::Index i = 0; i < m; ++i) {
    const double r2 = (fit.T_dst_src * Vec3(src.col(i)) - Vec3(dst.col(i))).squaredNorm();
    fit.sum_sq_mm2 += r2;
    fit.max_sq_mm2 = r2 > fit.max_sq_mm2 ? r2 : fit.max_sq_mm2;
  }
  return fit;
}

using FitWeights = std::array<double, kMaxMarkers>;

// Minimises sum_i w_i |T src_i - dst_i|^2 over the first m columns (3 <= m, w_i > 0).
// sum_sq_mm2 and max_sq_mm2 are the weighted squares w_i |r_i|^2.
inline RigidFit fit_rigid_weighted(const FitPoints& src, const FitPoints& dst, const FitWeights& w,
                                   int m) noexcept {
  double w_sum = 0.0;
  Vec3 src_mean = Vec3::Zero(), dst_mean = Vec3::Zero();
  for (Eigen::Index i = 0; i < m; ++i) {
    const double wi = w[static_cast<std::size_t>(i)];
    w_sum += wi;
    src_mean += wi * src.col(i);
    dst_mean += wi * dst.col(i);
  }
  src_mean /= w_sum;
  dst_mean /= w_sum;
  Mat3 H = Mat3::Zero();  // sum w (dst - dst_mean)(src - src_mean)^T
  for (Eigen::Index i = 0; i < m; ++i) {
    H += w[static_cast<std::size_t>(i)] * (Vec3(dst.col(i)) - dst_mean) *
         (Vec3(src.col(i)) - src_mean).transpose();
  }
  const Eigen::JacobiSVD<Mat3> svd(H, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Mat3 D = Mat3::Identity();
  if ((svd.matrixU() * svd.matrixV().transpose()).determinant() < 0.0) D(2, 2) = -1.0;
  RigidFit fit;
  fit.T_dst_src.linear() = svd.matrixU() * D * svd.matrixV().transpose();
  fit.T_dst_src.translation() = dst_mean - fit.T_dst_src.linear() * src_mean;
  for (Eigen::Index i = 0; i < m; ++i) {
    const double r2 = w[static_cast<std::size_t>(i)] *
                      (fit.T_dst_src * Vec3(src.col(i)) - Vec3(dst.col(i))).squaredNorm();
    fit.sum_sq_mm2 += r2;
    fit.max_sq_mm2 = r2 > fit.max_sq_mm2 ? r2 : fit.max_sq_mm2;
  }
  return fit;
}

}  // namespace mocap
