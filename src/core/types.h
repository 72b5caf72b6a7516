// Design: the few geometric value types every module shares.
// Frames are named in variables: T_world_body maps body coordinates to world
// coordinates (X_world = T_world_body * X_body), matching the spec's pose (R, t).
// Units: millimetres for lengths, radians for angles, pixels for image coordinates.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace mocap {

using Vec2 = Eigen::Vector2d;
using Vec3 = Eigen::Vector3d;
using Mat3 = Eigen::Matrix3d;
using Quat = Eigen::Quaterniond;
using Iso3 = Eigen::Isometry3d;

// Rigid transform built from rotation and translation (X_out = R * X_in + t).
inline Iso3 make_iso(const Mat3& R, const Vec3& t) {
  Iso3 T = Iso3::Identity();
  T.linear() = R;
  T.translation() = t;
  return T;
}

}  // namespace mocap
