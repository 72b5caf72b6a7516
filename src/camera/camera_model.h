// Design: the pinhole camera with OpenCV's 5-parameter distortion [k1 k2 p1 p2 k3],
// applied to normalised coordinates exactly as cv::projectPoints does:
//   x' = X_cam.x / X_cam.z, y' = X_cam.y / X_cam.z, r2 = x'^2 + y'^2
//   radial = 1 + k1 r2 + k2 r2^2 + k3 r2^3
//   x'' = x' radial + 2 p1 x' y' + p2 (r2 + 2 x'^2)
//   y'' = y' radial + p1 (r2 + 2 y'^2) + 2 p2 x' y'
//   u = fx x'' + cx,  v = fy y'' + cy      (pixel centre of the top-left pixel = (0,0))
// Extrinsics map world to camera: X_cam = R_cam_world * X_world + t_cam_world (mm).
// All functions are noexcept and allocation-free: they run on the hot path.
#pragma once

#include <array>
#include <string>
#include <vector>

#include "core/mat3_product.h"
#include "core/types.h"

namespace mocap {

struct CameraModel {
  std::string name;
  int width = 0;
  int height = 0;
  double fx = 0.0, fy = 0.0, cx = 0.0, cy = 0.0;
  std::array<double, 5> distortion{};  // k1, k2, p1, p2, k3
  Mat3 R_cam_world = Mat3::Identity();
  Vec3 t_cam_world = Vec3::Zero();

  Iso3 T_cam_world() const { return make_iso(R_cam_world, t_cam_world); }
  // Optical centre in world coordinates.
  Vec3 center_world() const { return -R_cam_world.transpose() * t_cam_world; }
};

struct Rig {
  std::vector<CameraModel> cameras;  // the first two form the stereo pair
};

// World -> camera coordinates, X_cam = R_cam_world * X_world + t_cam_world, written out
// (core/mat3_product.h: bit for bit Eigen's expression, without its out-of-line
// temporary) for the N-view merge's and the shape check's projections.
inline Vec3 to_camera(const CameraModel& cam, const Vec3& X_world) noexcept {
  return mul(cam.R_cam_world, X_world) + cam.t_cam_world;
}

// Normalised undistorted (x', y') -> normalised distorted (x'', y''). Inline with the
// pixel mapping and project() below: the N-view merge projects thousands of points per
// frame.
inline Vec2 distort_normalized(const CameraModel& cam, const Vec2& xn) noexcept {
  const auto& d = cam.distortion;
  const double x = xn.x(), y = xn.y();
  const double r2 = x * x + y * y;
  const double radial = 1.0 + r2 * (d[0] + r2 * (d[1] + r2 * d[4]));
  return Vec2(x * radial + 2.0 * d[2] * x * y + d[3] * (r2 + 2.0 * x * x),
              y * radial + d[2] * (r2 + 2.0 * y * y) + 2.0 * d[3] * x * y);
}
// Jacobian d(x'', y'') / d(x', y').
Eigen::Matrix2d distort_jacobian(const CameraModel& cam, const Vec2& xn) noexcept;

// Normalised undistorted -> pixel, and pixel -> normalised distorted.
inline Vec2 normalized_to_pixel(const CameraModel& cam, const Vec2& xn) noexcept {
  const Vec2 xd = distort_normalized(cam, xn);
  return Vec2(cam.fx * xd.x() + cam.cx, cam.fy * xd.y() + cam.cy);
}

// World point -> pixel. Returns false (px untouched) when the point is not in front
// of the camera (z <= 1e-9 mm).
bool project(const CameraModel& cam, const Vec3& X_world, Vec2& px) noexcept;
// Same, with the 2x3 Jacobian d(px)/d(X_world).
bool project(const CameraModel& cam, const Vec3& X_world, Vec2& px,
             Eigen::Matrix<double, 2, 3>& J_px_X) noexcept;
// The same projection and, when J is non-null, the same Jacobian as a row-major 2x3 array
// (J[0..2]: d(u)/d(X), J[3..5]: d(v)/d(X)): the distortion's 2x2 Jacobian times the
// pinhole's 2x3 times R, written out with no temporaries. Inline for the N-view merge's
// Gauss-Newton loop; project() above is this one.
inline bool project_jacobian(const CameraModel& cam, const Vec3& X_world, Vec2& px,
                             double* J) noexcept {
  const Mat3& R = cam.R_cam_world;
  const Vec3 Xc = to_camera(cam, X_world);
  if (!(Xc.z() > 1e-9)) return false;
  const double iz = 1.0 / Xc.z();
  const double x = Xc.x() * iz, y = Xc.y() * iz;
  const auto& d = cam.distortion;
  const double r2 = x * x + y * y;
  const double radial = 1.0 + r2 * (d[0] + r2 * (d[1] + r2 * d[4]));
  px = Vec2(cam.fx * (x * radial + 2.0 * d[2] * x * y + d[3] * (r2 + 2.0 * x * x)) + cam.cx,
            cam.fy * (y * radial + d[2] * (r2 + 2.0 * y * y) + 2.0 * d[3] * x * y) + cam.cy);
  if (J == nullptr) return true;
  const double dradial = d[0] + r2 * (2.0 * d[1] + 3.0 * r2 * d[4]);  // d(radial)/d(r2)
  const double fxz = cam.fx * iz, fyz = cam.fy * iz;
  const double a00 = fxz * (radial + 2.0 * x * x * dradial + 2.0 * d[2] * y + 6.0 * d[3] * x);
  const double a01 = fxz * (2.0 * x * y * dradial + 2.0 * d[2] * x + 2.0 * d[3] * y);
  const double a10 = fyz * (2.0 * x * y * dradial + 2.0 * d[2] * x + 2.0 * d[3] * y);
  const double a11 = fyz * (radial + 2.0 * y * y * dradial + 6.0 * d[2] * y + 2.0 * d[3] * x);
  // d(px)/d(Xc) = [a00 a01 -(a00 x + a01 y); a10 a11 -(a10 x + a11 y)], then times R.
  const double b02 = -(a00 * x + a01 * y), b12 = -(a10 * x + a11 * y);
  for (int c = 0; c < 3; ++c) {
    J[c] = a00 * R(0, c) + a01 * R(1, c) + b02 * R(2, c);
    J[3 + c] = a10 * R(0, c) + a11 * R(1, c) + b12 * R(2, c);
  }
  return true;
}

// Pixel -> normalised undistorted coordinates (x', y'): inverts the distortion by
// Gauss-Newton started from the fixed-point estimate; converges to < 1e-12 over the
// whole image for realistic lenses. Returns false when it did not converge.
bool undistort_pixel(const CameraModel& cam, const Vec2& px, Vec2& xn) noexcept;

// A ball's image is the section of the cone of rays tangent to it: an ellipse whose
// centre lies radially outwards of the projection of the ball's centre. With the ball
// seen at angle theta off the optical axis and angular radius beta (sin beta = radius /
// distance), the ellipse's centre is at tan(theta) (1 + tan^2 beta) / (1 - tan^2 theta
// tan^2 beta) in normalised coordinates (the midpoint of its major axis, tan(theta +
// beta) and tan(theta - beta)), and its half width across the radial direction is
// sin(beta) / sqrt(cos^2 theta - sin^2 beta). This inverts both: from the image centre
// (pixel) of the silhouette and its half width across the radial direction (pixels),
// the pixel of the ball's centre. For a 12 mm ball 2.5 m away and 20 degrees off axis
// the two differ by ~0.003 px: negligible for one point, but the same way in every
// frame. False (centre_px = silhouette_px) when the pixel cannot be undistorted or the
// radius is not positive.
bool ball_centre_pixel(const CameraModel& cam, const Vec2& silhouette_px, double radius_px,
                       Vec2& centre_px) noexcept;

// Unit ray direction in world coordinates through a pixel (false: no convergence).
bool pixel_ray_world(const CameraModel& cam, const Vec2& px, Vec3& dir_world) noexcept;

}  // namespace mocap
