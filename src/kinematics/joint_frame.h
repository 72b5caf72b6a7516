// Design: the paper's unique hinge-joint frame C = [c_x c_y c_z c] (Section 3.2), built
// from a point c on the axis and the axis direction c_z, both in one body's frame:
//   c_y = normalise(c x c_z),  c_x = c_y x c_z.
// The paper writes c_x = c_z x c_y, which makes [c_x c_y c_z] left-handed (det -1, not
// a rotation, unusable as a URDF origin); we take the right-handed c_x = c_y x c_z, i.e.
// the paper's c_x negated (docs/kinematics.md). When c is (nearly) parallel to c_z — the
// axis passes through the body origin — c x c_z is undefined: c_y is then taken from
// the basis axis least aligned with c_z (documented fallback), flagged `degenerate`.
#pragma once

#include "core/types.h"

namespace mocap::kinematics {

struct HingeFrame {
  Iso3 T_body_joint = Iso3::Identity();  // columns c_x, c_y, c_z; translation c
  bool degenerate = false;               // true when |c x c_z| < kMinLeverMm (fallback c_y)
};

// |c x c_z| (the axis' distance from the body origin) below this uses the fallback.
inline constexpr double kMinLeverMm = 1e-6;

// c: a point on the axis (mm, body frame); axis: direction (normalised internally).
HingeFrame make_hinge_frame(const Vec3& c, const Vec3& axis) noexcept;

}  // namespace mocap::kinematics
