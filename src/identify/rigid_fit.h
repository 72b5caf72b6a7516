// Design: least-squares rigid fit of m <= kMaxMarkers correspondences (no scaling), and
// its weighted form (weighted centroids and cross-covariance, Kabsch by a fixed-size 3x3
// SVD with the reflection fixed) for fits that mix whole and partial markers of different
// noise. The unweighted fit, the search's inner loop, is Horn's quaternion method solved
// as in QCP (Theobald 2005): the largest eigenvalue of Horn's traceless 4x4 matrix by
// Newton's method on its characteristic quartic (from above: monotone), the quaternion
// from the adjugate of N - lambda I (its largest column). It is the same optimum as
// Eigen::umeyama's (the rotation maximising tr(R^T Sigma) over SO(3), i.e. the SVD's with
// the reflection fixed) to ~1e-12 relative, at a fraction of the cost of the 3x3 Jacobi
// SVD; when that optimum is nearly degenerate (two top eigenvalues within ~1e-4 of the
// scale: nearly collinear points, coincident points) the fit falls back to
// Eigen::umeyama. The point matrices have a fixed maximum size, so nothing allocates:
// usable in the hot path. The bodies live in rigid_fit.cpp: the SVD templates cost every
// includer ~1.7 s of compile time otherwise.
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

// The same fit by Eigen::umeyama (3x3 Jacobi SVD): fit_rigid's fallback, and the
// reference of its tests and benchmark.
RigidFit fit_rigid_umeyama(const FitPoints& src, const FitPoints& dst, int m) noexcept;

using FitWeights = std::array<double, kMaxMarkers>;

// Minimises sum_i w_i |T src_i - dst_i|^2 over the first m columns (3 <= m, w_i > 0).
// sum_sq_mm2 and max_sq_mm2 are the weighted squares w_i |r_i|^2.
RigidFit fit_rigid_weighted(const FitPoints& src, const FitPoints& dst, const FitWeights& w,
                            int m) noexcept;

}  // namespace mocap
