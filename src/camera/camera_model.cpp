#include "camera/camera_model.h"

#include <Eigen/LU>
#include <algorithm>
#include <cmath>

namespace mocap {

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

bool project(const CameraModel& cam, const Vec3& X_world, Vec2& px) noexcept {
  const Vec3 Xc = to_camera(cam, X_world);
  if (!(Xc.z() > 1e-9)) return false;
  px = normalized_to_pixel(cam, Vec2(Xc.x() / Xc.z(), Xc.y() / Xc.z()));
  return true;
}

bool project(const CameraModel& cam, const Vec3& X_world, Vec2& px,
             Eigen::Matrix<double, 2, 3>& J_px_X) noexcept {
  double J[6];
  if (!project_jacobian(cam, X_world, px, J)) return false;
  J_px_X << J[0], J[1], J[2], J[3], J[4], J[5];
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

namespace {

// Where an edge fit finds the centre of the image of a ball whose centre projects to xc
// (normalised undistorted) and whose tangent cone has half angle asin(sin_b). The
// silhouette is an ellipse centred at xe with semi-axes a (radial, u) and b (across, v).
// The lens maps it to x(phi) = d(xe) + J (a cos u + b sin v) + P cos^2 + Q cos sin +
// R sin^2 (P, Q, R: its second differences over the semi-axes). An edge fit undoes the
// expected radial stretch s = |J a u| / |J b v| and fits a circle: its centre is the
// first Fourier harmonic of the radius, which takes the quadratic terms' constant part
// and half of their second harmonic: along u 3/4 P + 1/4 R + s/4 Q (v component of Q),
// across 1/4 P + 3/4 R + 1/(4 s) Q (u component). Normalised distorted coordinates.
Vec2 ball_image_centre(const CameraModel& cam, const Vec2& xc, double sin_b) noexcept {
  const double t = xc.norm();
  const Vec2 u = t > 1e-12 ? Vec2(xc / t) : Vec2(1.0, 0.0);
  const Vec2 v(-u.y(), u.x());
  const double th = std::atan(t), beta = std::asin(std::clamp(sin_b, 0.0, 0.5));
  const double t_plus = std::tan(th + beta), t_minus = std::tan(th - beta);
  const Vec2 xe = u * (0.5 * (t_plus + t_minus));
  const double a = 0.5 * (t_plus - t_minus);
  const double cos_t = std::cos(th);
  const double b = sin_b / std::sqrt(std::max(cos_t * cos_t - sin_b * sin_b, 1e-12));
  auto d = [&](const Vec2& x) { return distort_normalized(cam, x); };
  const Vec2 d0 = d(xe);
  const Vec2 P = 0.5 * (d(xe + a * u) + d(xe - a * u) - 2.0 * d0);
  const Vec2 R = 0.5 * (d(xe + b * v) + d(xe - b * v) - 2.0 * d0);
  const Vec2 Q = 0.25 * (d(xe + a * u + b * v) - d(xe + a * u - b * v) - d(xe - a * u + b * v) +
                         d(xe - a * u - b * v));
  const Eigen::Matrix2d J = distort_jacobian(cam, xe);
  const double s = (J * u).norm() * a / std::max((J * v).norm() * b, 1e-300);
  const double along = 0.75 * P.dot(u) + 0.25 * R.dot(u) + 0.25 * s * Q.dot(v);
  const double across = 0.25 * P.dot(v) + 0.75 * R.dot(v) + 0.25 / s * Q.dot(u);
  return d0 + along * u + across * v;
}

}  // namespace

bool ball_centre_pixel(const CameraModel& cam, const Vec2& silhouette_px, double radius_px,
                       Vec2& centre_px) noexcept {
  centre_px = silhouette_px;
  Vec2 xm;
  if (!(radius_px > 0.0) || !(cam.fx > 0.0) || !(cam.fy > 0.0) ||
      !undistort_pixel(cam, silhouette_px, xm))
    return false;
  const Vec2 m(silhouette_px.x() - cam.cx, silhouette_px.y() - cam.cy);
  const Vec2 m_norm(m.x() / cam.fx, m.y() / cam.fy);  // normalised distorted
  // The half width across the radial direction in normalised undistorted units: the
  // pixels over the focal length and the lens's local magnification across.
  const double tm = xm.norm();
  const Vec2 v = tm > 1e-12 ? Vec2(-xm.y() / tm, xm.x() / tm) : Vec2(0.0, 1.0);
  const Vec2 jv = distort_jacobian(cam, xm) * v;
  const double b_meas = radius_px / Vec2(cam.fx * jv.x(), cam.fy * jv.y()).norm();
  // Fixed point on the ball's centre xc (the correction is second order in beta).
  Vec2 xc = xm;
  for (int round = 0; round < 4; ++round) {
    const double cos_t = 1.0 / std::sqrt(1.0 + xc.squaredNorm());
    const double sin_b = b_meas * cos_t / std::sqrt(1.0 + b_meas * b_meas);
    const Vec2 predicted = ball_image_centre(cam, xc, sin_b);
    // Move xc by the mismatch, mapped back through the lens's local Jacobian.
    const Eigen::Matrix2d J = distort_jacobian(cam, xc);
    xc += J.inverse() * (m_norm - predicted);
  }
  centre_px = normalized_to_pixel(cam, xc);
  return std::isfinite(centre_px.x()) && std::isfinite(centre_px.y());
}

}  // namespace mocap
