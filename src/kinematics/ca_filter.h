// Design: the one constant-acceleration Kalman filter of the project's causal rates, for a
// single coordinate (a joint angle, a body position coordinate, a body rotation
// coordinate), with the noise models adapted from the measurements themselves. Used by
// JointRateFilter (joint_rates.h) and BodyRateFilter (body_rates.h); the derivation of the
// adaptation is in docs/kinematics.md, "Joint rates".
//  - State: value, rate, acceleration; white-jerk process noise of spectral density
//    q = q_base x lambda. The covariance is kept as the six numbers of its upper triangle
//    (no Eigen temporaries: it runs ~130 times a frame on the humanoid).
//  - Measurement variance: the stated variance times kappa, the running mean of (third
//    difference of the measurements)^2 over the variance the stated values predict for it
//    (v0 + 9 v1 + 9 v2 + v3); over 10 ms a robot's jerk moves a third difference by far
//    less than the noise, so kappa is 1 when the stated noise is right.
//  - Process-noise scale lambda: driven by the running mean of the normalised innovation
//    squared (1 for a consistent filter).
// CaClock keeps the times shared by the coordinates of one joint or body (the last four,
// to tell whether the third difference is of equally spaced samples). Everything is
// noexcept and allocation-free.
#pragma once

#include <array>
#include <cstdint>

namespace mocap::kinematics {

// The per-step quantities every coordinate of one joint or body shares.
struct CaStep {
  double dt_s = 0.0;           // since the previous measurement
  double a_nis = 0.0;          // weight of this step in the NIS running mean
  double a_kappa = 0.0;        // weight of this step in the kappa running mean
  int slot = 0;                // where this measurement goes in the history
  bool shift = false;          // the history was full: shift it first
  bool equal_spacing = false;  // the four samples are equally spaced (third differences)
};

// Times of one joint's or body's measurements.
struct CaClock {
  bool active = false;   // a filter runs (observed within the gap bound)
  int observations = 0;  // since the last restart
  std::int64_t t_last_ns = 0;
  std::array<std::int64_t, 4> t_hist{};
  int hist = 0;  // valid entries of t_hist

  void restart(std::int64_t t_ns) noexcept;
  // The step to t_ns (> t_last_ns); advances the history and t_last_ns.
  CaStep advance(std::int64_t t_ns) noexcept;
};

struct CaAxis {
  std::array<double, 3> x{};  // value, rate, acceleration (continuous, never wrapped)
  std::array<double, 6> P{};  // covariance, upper triangle: 00 01 02 11 12 22
  std::array<double, 4> z{};  // the last measurements (continuous), oldest first
  std::array<double, 4> v{};  // their stated variances
  double nis_mean = 1.0;      // running mean of the normalised innovation squared
  double lambda = 1.0;        // process-noise scale
  double kappa = 1.0;         // measurement-noise scale

  // Starts at measurement z with stated variance v; rate and acceleration unknown (their
  // sds given). The noise scales are kept: they describe the coordinate's measurement and
  // motion, which a short loss of sight does not change.
  void restart(double z0, double v0, double rate_sd, double accel_sd) noexcept;
  // Predicts by s.dt_s with jerk density q_base (x lambda), then updates with the
  // innovation y (measurement minus predicted value, already made continuous by the
  // caller) of stated variance v0.
  void step(const CaStep& s, double q_base, double y, double v0) noexcept;
  // The value predicted s.dt_s ahead (for the caller's innovation; no state change).
  double predicted_value(double dt_s) const noexcept {
    return x[0] + (dt_s * x[1] + 0.5 * dt_s * dt_s * x[2]);
  }
  double rate_sd() const noexcept;
};

}  // namespace mocap::kinematics
