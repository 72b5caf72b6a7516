// Design: rotation conventions shared by the formats, the simulator's ground truth
// and the joint-angle stage, so that every producer and consumer agrees.
//  - Quaternions are Hamilton, unit norm, with qw >= 0 (spec).
//  - Ball-joint angles (a0, a1, a2) are intrinsic X-Y'-Z'' Euler angles of the child's
//    rotation relative to the parent, R_rel = R_parent^T * R_child = Rx(a0)*Ry(a1)*Rz(a2).
//    a1 lies in [-pi/2, pi/2]; at the gimbal lock (|a1| = pi/2) a2 is set to 0.
#pragma once

#include <cmath>

#include "core/types.h"

namespace mocap {

// Unit quaternion of a rotation matrix with the spec's sign convention (qw >= 0).
inline Quat canonical_quat(const Mat3& R) noexcept {
  Quat q(R);
  q.normalize();
  if (q.w() < 0.0) q.coeffs() = -q.coeffs();
  return q;
}

inline Mat3 rot_x(double a) noexcept { return Eigen::AngleAxisd(a, Vec3::UnitX()).toRotationMatrix(); }
inline Mat3 rot_y(double a) noexcept { return Eigen::AngleAxisd(a, Vec3::UnitY()).toRotationMatrix(); }
inline Mat3 rot_z(double a) noexcept { return Eigen::AngleAxisd(a, Vec3::UnitZ()).toRotationMatrix(); }

// R = Rx(a0) * Ry(a1) * Rz(a2).
inline Mat3 euler_xyz_to_rotation(const Vec3& a) noexcept {
  return rot_x(a[0]) * rot_y(a[1]) * rot_z(a[2]);
}

// Inverse of euler_xyz_to_rotation. R(0,2) = sin(a1).
inline Vec3 rotation_to_euler_xyz(const Mat3& R) noexcept {
  const double s1 = std::fmax(-1.0, std::fmin(1.0, R(0, 2)));
  const double a1 = std::asin(s1);
  if (std::abs(s1) > 1.0 - 1e-12) {  // gimbal lock: only a0 + a2 (or a0 - a2) is defined
    const double a0 = std::atan2(R(2, 1), R(1, 1));
    return Vec3(a0, a1, 0.0);
  }
  const double a0 = std::atan2(-R(1, 2), R(2, 2));
  const double a2 = std::atan2(-R(0, 1), R(0, 0));
  return Vec3(a0, a1, a2);
}

// True when R is a proper rotation within tol (orthonormal, det +1).
inline bool is_rotation(const Mat3& R, double tol = 1e-6) noexcept {
  return (R.transpose() * R - Mat3::Identity()).cwiseAbs().maxCoeff() < tol &&
         std::abs(R.determinant() - 1.0) < tol;
}

}  // namespace mocap
