// Design: the linear joint estimators of the paper's Section 3 (after Gamage & Lasenby).
// Input: relative poses T_i = T_world_parent^-1 * T_world_child = [R_i t_i] (child -> parent).
//  - Ball (Eq. 2): min || [I -R_i] [c1; c2] - t_i ||^2 over all i; c1 = centre in the
//    parent frame, c2 = the same point in the child frame. Solved by SVD of the
//    column-equilibrated 3N x 6 matrix M (every column of M has norm sqrt(N): scaling by
//    1/sqrt(N) makes the singular values dimensionless and comparable between recordings).
//  - SCoRE form: the same unknowns from world poses, R_p c1 + t_p = R_c c2 + t_c. Each
//    3-row block is the Eq. 2 block multiplied by the orthogonal R_p, so both have the same
//    singular values and the same solution in exact arithmetic (tested; docs compare).
//  - Hinge: M_5, the closest rank-5 approximation of M; its null vector (a1; a2) gives the
//    axis in both frames, and the minimum-norm solution x = M_5^+ t the point (c1; c2).
// Degeneracy: the normalised singular values s_k = sigma_k / sqrt(N) of M depend only on
// the rotations. With rotation-vector variances v1 >= v2 >= v3 about the principal axes
// (small-angle analysis, docs/kinematics.md), the three smallest are ~ sqrt((v2+v3)/2),
// sqrt((v1+v3)/2), sqrt((v1+v2)/2): an rms rotation in rad, reported in degrees. A ball
// needs s6 >= min_motion_deg; a hinge needs s5 >= min_motion_deg and s6/s5 <= the
// off-axis ratio. Failures are Expected errors quoting the numbers.
#pragma once

#include <array>
#include <string>
#include <vector>

#include "core/expected.h"
#include "core/types.h"

namespace mocap::kinematics {

struct RelativePose {
  Mat3 R_parent_child = Mat3::Identity();  // X_parent = R * X_child + t
  Vec3 t_parent_child = Vec3::Zero();      // mm
};

struct LinearOptions {
  int min_poses = 6;                       // fewer poses: error
  double min_motion_deg = 2.0;             // ball: s6; hinge: s5 (degree-equivalent)
  double max_hinge_off_axis_ratio = 0.25;  // hinge: s6 / s5 above this is not a hinge
};

struct LinearDiagnostics {
  int poses = 0;
  std::array<double, 6> singular_values{};  // s_k = sigma_k / sqrt(N), descending
  double residual_rms_mm = 0.0;             // || M x - t || / sqrt(N)
  // s_k in degrees (s_k * 180 / pi) for messages.
  double singular_value_deg(int k) const noexcept;
  std::string describe() const;  // "N poses, normalised singular values [...]"
};

struct BallEstimate {
  Vec3 center_parent = Vec3::Zero();
  Vec3 center_child = Vec3::Zero();
  LinearDiagnostics diagnostics;
};

struct HingeEstimate {
  Vec3 center_parent = Vec3::Zero();  // minimum-norm point of M_5 x = t (docs)
  Vec3 center_child = Vec3::Zero();
  Vec3 axis_parent = Vec3::UnitZ();  // unit; sign: axis_parent . sign_hint >= 0
  Vec3 axis_child = Vec3::UnitZ();
  LinearDiagnostics diagnostics;
};

RelativePose relative_pose(const Iso3& T_world_parent, const Iso3& T_world_child) noexcept;

// `label` prefixes error messages, e.g. "calibration: joint 'shoulder' (ball)".
Expected<BallEstimate> estimate_ball(const std::vector<RelativePose>& poses,
                                     const LinearOptions& options, const std::string& label);

// SCoRE-style world formulation (same minimiser as estimate_ball, see above).
Expected<BallEstimate> estimate_ball_world(const std::vector<Iso3>& T_world_parent,
                                           const std::vector<Iso3>& T_world_child,
                                           const LinearOptions& options, const std::string& label);

Expected<HingeEstimate> estimate_hinge(const std::vector<RelativePose>& poses,
                                       const LinearOptions& options, const std::string& label,
                                       const Vec3& sign_hint_parent = Vec3::UnitZ());

}  // namespace mocap::kinematics
