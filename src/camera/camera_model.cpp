#include "camera/camera_model.h"

#include <cmath>

namespace mocap {

Vec2 distort_normalized(const CameraModel& cam, const Vec2& xn) noexcept {
  const auto& d = cam.distortion;
  const double x = xn.x(), y = xn.y();
  const double r2 = x * x + y * y;
  const double radial = 1.0 + r2 * (d[0] + r2 * (d[1] + r2 * d[4]));
  return Vec2(x * radial + 2.0 * d[2] * x * y + d[3] * (r2 + 2.0 * x * x),
              y * radial + d[2] * (r2 + 2.0 * y * y) + 2.0 * d[3] * x * y);
}

Eigen::Matrix2d distort_jacobian(const CameraModel& cam, const Vec2& xn) noexcept {
  const auto& d = cam.distortion;
  const double x = xn.x(), y = xn.y();
  const double r2 = x * x + y * y;
  const double radial = 1.0 + r2 * (d[0] + r2 * (d[1] + r2 * d[4]));
  // d(radial)/d(r2)
  const double dradial = d[0] + r2 * (2.0 * d[1] + 3.0 * r2 * d[4]);
  Eigen::Matrix2d J;
  J(0, 0) = radial + x * dradial * 2.0 * x + 2.0 * d[2] * y + d[3] * 6.0 * x;
  J(0, 1) = x * dradial * 2.0 * y + 2.0 * d[2] * x + d[3] * 2.0 * y;
  J(1, 0) = y * dradial * 2.0 * x + d[2] * 2.0 * x + 2.0 * d[3] * y;
  J(1, 1) = radial + y * dradial * 2.0 * y + d[2] * 6.0 * y + 2.0 * d[3] * x;
  return J;
}

Vec2 normalized_to_pixel(const CameraModel& cam, const Vec2& xn) noexcept {
  const Vec2 xd = distort_normalized(cam, xn);
  return Vec2(cam.fx * xd.x() + cam.cx, cam.fy * xd.y() + cam.cy);
}

bool project(const CameraModel& cam, const Vec3& X_world, Vec2& px) noexcept {
  const Vec3 Xc = cam.R_cam_world * X_world + cam.t_cam_world;
  if (!(Xc.z() > 1e-9)) return false;
  px = normalized_to_pixel(cam, Vec2(Xc.x() / Xc.z(), Xc.y() / Xc.z()));
  return true;
}

bool project(const CameraModel& cam, const Vec3& X_world, Vec2& px,
             Eigen::Matrix<double, 2, 3>& J_px_X) noexcept {
  const Vec3 Xc = cam.R_cam_world * X_world + cam.t_cam_world;
  if (!(Xc.z() > 1e-9)) return false;
  const double iz = 1.0 / Xc.z();
  const Vec2 xn(Xc.x() * iz, Xc.y() * iz);
  px = normalized_to_pixel(cam, xn);
  Eigen::Matrix<double, 2, 3> J_xn_Xc;
  J_xn_Xc << iz, 0.0, -xn.x() * iz, 0.0, iz, -xn.y() * iz;
  Eigen::Matrix2d F = Eigen::Matrix2d::Zero();
  F(0, 0) = cam.fx;
  F(1, 1) = cam.fy;
  J_px_X = F * distort_jacobian(cam, xn) * J_xn_Xc * cam.R_cam_world;
  return true;
}

bool undistort_pixel(const CameraModel& cam, const Vec2& px, Vec2& xn) noexcept {
  const Vec2 xd((px.x() - cam.cx) / cam.fx, (px.y() - cam.cy) / cam.fy);
  // Fixed-point start (OpenCV's scheme), a few steps.
  const auto& d = cam.distortion;
  Vec2 x = xd;
  for (int i = 0; i < 5; ++i) {
    const double r2 = x.squaredNorm();
    const double radial = 1.0 + r2 * (d[0] + r2 * (d[1] + r2 * d[4]));
    const double dx = 2.0 * d[2] * x.x() * x.y() + d[3] * (r2 + 2.0 * x.x() * x.x());
    const double dy = d[2] * (r2 + 2.0 * x.y() * x.y()) + 2.0 * d[3] * x.x() * x.y();
    if (!(std::abs(radial) > 1e-12)) break;
    x = Vec2((xd.x() - dx) / radial, (xd.y() - dy) / radial);
  }
  // Gauss-Newton (a 2x2 Newton step) to full precision.
  for (int i = 0; i < 30; ++i) {
    const Vec2 r = distort_normalized(cam, x) - xd;
    if (r.squaredNorm() < 1e-28) {
      xn = x;
      return true;
    }
    const Eigen::Matrix2d J = distort_jacobian(cam, x);
    const double det = J.determinant();
    if (!(std::abs(det) > 1e-15)) return false;
    x -= J.inverse() * r;
    if (!std::isfinite(x.x()) || !std::isfinite(x.y())) return false;
  }
  const Vec2 r = distort_normalized(cam, x) - xd;
  if (r.norm() < 1e-10) {
    xn = x;
    return true;
  }
  return false;
}

bool pixel_ray_world(const CameraModel& cam, const Vec2& px, Vec3& dir_world) noexcept {
  Vec2 xn;
  if (!undistort_pixel(cam, px, xn)) return false;
  dir_world = (cam.R_cam_world.transpose() * Vec3(xn.x(), xn.y(), 1.0)).normalized();
  return true;
}

}  // namespace mocap
