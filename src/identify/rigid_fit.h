// Design: least-squares rigid fit of m <= kMaxMarkers correspondences with
// Eigen::umeyama (no scaling). The point matrices have a fixed maximum size, so Eigen
// allocates nothing: usable in the hot path.
#pragma once

#include <Eigen/Geometry>

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

}  // namespace mocap
