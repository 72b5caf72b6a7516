// Design: least-squares rigid fit of m <= kMaxMarkers correspondences with
// Eigen::umeyama (no scaling), and its weighted form (weighted centroids and cross-
// covariance, Kabsch by a fixed-size 3x3 SVD with the reflection fixed) for fits that mix
// whole and partial markers of different noise. The point matrices have a fixed maximum
// size, so Eigen allocates nothing: usable in the hot path. The bodies live in
// rigid_fit.cpp: the SVD templates cost every includer ~1.7 s of compile time otherwise.
#pragma once

#include <Eigen/Core>
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
RigidFit fit_rigid(const FitPoints& src, const FitPoints& dst, int m) noexcept;

using FitWeights = std::array<double, kMaxMarkers>;

// Minimises sum_i w_i |T src_i - dst_i|^2 over the first m columns (3 <= m, w_i > 0).
// sum_sq_mm2 and max_sq_mm2 are the weighted squares w_i |r_i|^2.
RigidFit fit_rigid_weighted(const FitPoints& src, const FitPoints& dst, const FitWeights& w,
                            int m) noexcept;

}  // namespace mocap
