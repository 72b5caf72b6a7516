// Design: see rigid_fit.h.
#include "identify/rigid_fit.h"

#include <Eigen/Geometry>
#include <Eigen/SVD>

namespace mocap {

RigidFit fit_rigid(const FitPoints& src, const FitPoints& dst, int m) noexcept {
  RigidFit fit;
  fit.T_dst_src.matrix() = Eigen::umeyama(src.leftCols(m), dst.leftCols(m), false);
  for (Eigen::Index i = 0; i < m; ++i) {
    const double r2 = (fit.T_dst_src * Vec3(src.col(i)) - Vec3(dst.col(i))).squaredNorm();
    fit.sum_sq_mm2 += r2;
    fit.max_sq_mm2 = r2 > fit.max_sq_mm2 ? r2 : fit.max_sq_mm2;
  }
  return fit;
}

RigidFit fit_rigid_weighted(const FitPoints& src, const FitPoints& dst, const FitWeights& w,
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
