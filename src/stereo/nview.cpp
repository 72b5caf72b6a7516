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
                         double& rms_px, int max_iterations) noexcept {
  if (n < 1 || n > kMaxCameras) return false;
  Vec3 X = X_world;
  bool last = max_iterations <= 0;
  for (int it = 0;; ++it) {
    Mat3 H = Mat3::Zero();
    Vec3 g = Vec3::Zero();
    double sq = 0.0;
    for (int k = 0; k < n; ++k) {
      Vec2 p;
      Eigen::Matrix<double, 2, 3> J;
      if (!project(*cams[k], X, p, J)) return false;
      const Vec2 r = p - px[k];
      sq += r.squaredNorm();
      H.noalias() += J.transpose() * J;
      g.noalias() += J.transpose() * r;
    }
    rms_px = std::sqrt(sq / static_cast<double>(n));
    X_world = X;
    if (last) break;
    const Eigen::LDLT<Mat3> ldlt(H);
    if (ldlt.info() != Eigen::Success) break;
    const Vec3 step = ldlt.solve(g);
    if (!step.allFinite()) break;
    X -= step;
    // After a converged step (or the last allowed one) evaluate once more and stop.
    last = step.norm() < 1e-9 || it + 1 >= max_iterations;
  }
  return true;
}

}  // namespace mocap
