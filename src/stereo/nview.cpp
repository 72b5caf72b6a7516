// Design: see nview.h.
#include "stereo/nview.h"

#include <Eigen/Cholesky>
#include <Eigen/SVD>
#include <cmath>

namespace mocap {

bool triangulate_linear_nview(const CameraModel* const* cams, const Vec2* xn, int n,
                              Vec3& X_world) noexcept {
  if (n < 2 || n > kMaxCameras) return false;
  Vec3 mean = Vec3::Zero();
  for (int k = 0; k < n; ++k) mean += cams[k]->center_world();
  mean /= static_cast<double>(n);
  double scale = 0.0;
  for (int k = 0; k < n; ++k) scale += (cams[k]->center_world() - mean).norm();
  scale /= static_cast<double>(n);
  if (!(scale > 0.0)) return false;
  using MatA = Eigen::Matrix<double, Eigen::Dynamic, 4, 0, 2 * kMaxCameras, 4>;
  MatA A(2 * n, 4);
  for (int k = 0; k < n; ++k) {
    // X_world = mean + scale * Y  =>  X_cam = R (mean + scale Y) + t.
    Eigen::Matrix<double, 3, 4> P;
    P.leftCols<3>() = cams[k]->R_cam_world;
    P.col(3) = (cams[k]->R_cam_world * mean + cams[k]->t_cam_world) / scale;
    A.row(2 * k) = xn[k].x() * P.row(2) - P.row(0);
    A.row(2 * k + 1) = xn[k].y() * P.row(2) - P.row(1);
  }
  const Eigen::JacobiSVD<MatA> svd(A, Eigen::ComputeFullV);
  const Eigen::Vector4d Y = svd.matrixV().col(3);
  if (!(std::abs(Y(3)) > 1e-15 * Y.head<3>().norm())) return false;
  const Vec3 X = mean + scale * Y.head<3>() / Y(3);
  for (int k = 0; k < n; ++k)
    if (!((cams[k]->R_cam_world * X + cams[k]->t_cam_world).z() > 0.0)) return false;
  X_world = X;
  return true;
}

bool refine_gauss_newton(const CameraModel* const* cams, const Vec2* px, int n, Vec3& X_world,
                         double& rms_px, int max_iterations, double step_tolerance_mm,
                         double* r2_px) noexcept {
  if (n < 1 || n > kMaxCameras) return false;
  Vec3 X = X_world;
  bool last = max_iterations <= 0;
  for (int it = 0;; ++it) {
    // Normal equations H step = g, H = sum J^T J (upper triangle), g = sum J^T r.
    double h00 = 0, h01 = 0, h02 = 0, h11 = 0, h12 = 0, h22 = 0, g0 = 0, g1 = 0, g2 = 0;
    double sq = 0.0;
    for (int k = 0; k < n; ++k) {
      Vec2 p;
      double J[6];
      if (!project_jacobian(*cams[k], X, p, last ? nullptr : J)) return false;
      const Vec2 r = p - px[k];
      const double r2 = r.squaredNorm();
      sq += r2;
      if (r2_px != nullptr) r2_px[k] = r2;
      if (last) continue;
      const double* u = J;
      const double* v = J + 3;
      h00 += u[0] * u[0] + v[0] * v[0];
      h01 += u[0] * u[1] + v[0] * v[1];
      h02 += u[0] * u[2] + v[0] * v[2];
      h11 += u[1] * u[1] + v[1] * v[1];
      h12 += u[1] * u[2] + v[1] * v[2];
      h22 += u[2] * u[2] + v[2] * v[2];
      g0 += u[0] * r.x() + v[0] * r.y();
      g1 += u[1] * r.x() + v[1] * r.y();
      g2 += u[2] * r.x() + v[2] * r.y();
    }
    rms_px = std::sqrt(sq / static_cast<double>(n));
    X_world = X;
    if (last) break;
    // Cholesky of the 3x3 (positive definite with two or more views not on one ray; a
    // non-positive pivot: no step, as an LDLT failure).
    const double l00 = h00;
    if (!(l00 > 0.0)) break;
    const double l10 = h01 / l00, l20 = h02 / l00;
    const double l11 = h11 - l10 * h01;
    if (!(l11 > 0.0)) break;
    const double l21 = (h12 - l20 * h01) / l11;
    const double l22 = h22 - l20 * h02 - l21 * l21 * l11;
    if (!(l22 > 0.0)) break;
    // L D L^T: forward (unit lower), divide by D, backward.
    const double y0 = g0, y1 = g1 - l10 * y0, y2 = g2 - l20 * y0 - l21 * y1;
    const double z2 = y2 / l22, z1 = y1 / l11 - l21 * z2, z0 = y0 / l00 - l10 * z1 - l20 * z2;
    const Vec3 step(z0, z1, z2);
    if (!step.allFinite()) break;
    X -= step;
    // After a converged step (or the last allowed one) evaluate once more and stop.
    last = step.norm() < step_tolerance_mm || it + 1 >= max_iterations;
  }
  return true;
}

}  // namespace mocap
