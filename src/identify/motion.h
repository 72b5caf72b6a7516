// Design: the motion model of the temporal path: the track of a body (its last two
// poses), the constant-velocity prediction, the gate around each predicted marker and
// the speed limits (the "jump gate"). Every bound is derived from the stated limits of
// IdentifyConfig, the time since the body was last seen and the 3D noise, never from a
// scene:
//  - prediction: the last world-frame motion dT = T_last * T_prev^-1 is a screw (a
//    rotation about an axis plus a translation along it); it is continued for the new
//    time step, T = exp(r * log dT) * T_last, r = age / interval. Unlike extrapolating the
//    body origin and the rotation separately, this does not depend on where the target's
//    frame lies (an origin at a joint or at the world origin, a metre from its markers),
//    and it is exact for a constant twist (a limb swinging about a fixed axis).
//  - gate (per marker, around its predicted position): the prediction error plus noise.
//    With constant velocity, a marker whose acceleration is at most a deviates from the
//    extrapolation of its last two positions by at most a * age * (age + interval) / 2
//    (Taylor), and never more than 2 * v_max * age; with constant pose (or a single
//    pose) by v_max * age. a is max_acceleration_mm_per_s2, or v_max * w_max when that
//    is 0 (a marker at the speed limit turning at the angular limit). Noise: the
//    extrapolation weighs the last fitted positions by (1 + r) and r, the new point adds
//    its own. Noise of a fitted pose at a marker (3-D mean square): with m matched
//    markers at offsets q_i from their centroid, J = sum(|q_i|^2 I - q_i q_i^T), the fit's
//    translation has variance sigma^2 / m per axis and its rotation sigma^2 J^-1, so a
//    marker at offset q moves by sigma^2 (3 / m + |q|^2 tr J^-1 - q^T J^-1 q); a nearly
//    collinear triangle (rotation about its line unknown) gives its far markers a large
//    one. The gate adds (1 + r)^2 of the last pose's, r^2 of the previous one's and the
//    new point's 3 sigma^2, and takes q * sqrt(sum), q the 3-D chi quantile at
//    consistency_confidence (a bound for any shape of the covariance: its largest
//    eigenvalue is at most its trace). Capped at half the target's smallest marker
//    distance (the gates of one body never overlap). Without any stated limit the
//    configured warm_gate_mm, scaled by age / interval, is the gate (former behaviour).
//  - speed limits: between the last pose and a new one, no marker of the target may
//    move more than v_max * age + q * sqrt(u_last^2 + u_new^2) (the two poses' noise at
//    that marker), and the rotation may not exceed w_max * age + q * sigma *
//    sqrt(tr J_last^-1 + tr J_new^-1). Measured on the markers, not on the frame's
//    origin, so they are the same for any choice of body frame.
#pragma once

#include <array>
#include <cstdint>

#include "identify/identify_types.h"
#include "identify/target_model.h"

namespace mocap {

// The noise of a fitted pose (see above): per marker of the target, and of its rotation.
struct PoseNoise {
  std::array<double, kMaxMarkers> marker_var_mm2{};  // 3-D mean square displacement
  double angle_var_rad2 = 0.0;
};

struct MotionTrack {
  bool valid = false;
  PoseNoise noise_last, noise_prev;
  bool has_prev = false;
  Iso3 T_last = Iso3::Identity();
  std::int64_t t_last_ns = 0;
  Iso3 T_prev = Iso3::Identity();
  std::int64_t t_prev_ns = 0;
};

class MotionBounds {
 public:
  MotionBounds() = default;
  explicit MotionBounds(const IdentifyConfig& config) noexcept;

  Iso3 predict(const MotionTrack& track, std::int64_t t_ns) const noexcept;
  // Radius of the gate around each predicted marker of `model` at t_ns (mm).
  void gates_mm(const MotionTrack& track, std::int64_t t_ns, const TargetModel& model,
                std::array<double, kMaxMarkers>& gate_mm) const noexcept;
  // The noise of a pose fitted on the markers c with point_of_marker[c] >= 0.
  PoseNoise pose_noise(const TargetModel& model,
                       const std::array<std::int16_t, kMaxMarkers>& point_of_marker) const noexcept;
  // False when T (at t_ns, noise `now`) is farther from the track's last pose than the
  // limits allow.
  bool within_limits(const MotionTrack& track, const Iso3& T, const PoseNoise& now,
                     std::int64_t t_ns, const TargetModel& model) const noexcept;
  double acceleration_mm_per_s2() const noexcept { return accel_; }
  double quantile() const noexcept { return q_; }  // q, the 3-D chi quantile

 private:
  bool constant_velocity_ = true;
  double v_max_ = 0.0;  // mm/s, 0: none
  double w_max_ = 0.0;  // rad/s, 0: none
  double accel_ = 0.0;  // mm/s^2, 0: none
  double q_ = 0.0;
  double sigma2_ = 0.0;  // mm^2, per coordinate
  double legacy_gate_mm_ = 15.0;
};

// SE(3) helpers of the prediction (exposed for the tests): log of a rigid motion as
// (rotation vector, translation part v with T.t = V(w) v) and its exponential.
void se3_log(const Iso3& T, Vec3& w, Vec3& v) noexcept;
Iso3 se3_exp(const Vec3& w, const Vec3& v) noexcept;

}  // namespace mocap
