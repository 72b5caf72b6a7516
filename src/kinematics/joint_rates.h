// Design: causal joint rates (the velocities of a0..a2) and their standard deviations,
// estimated live on the identify thread from the angles of each frame (docs/kinematics.md,
// "Joint rates"). Immutable configuration plus preallocated per-degree-of-freedom state,
// sized once by create(); update() is noexcept and allocation-free.
//
// Each degree of freedom (a ball joint's three angles, a hinge's one) has its own
// constant-acceleration Kalman filter (state: angle, rate, acceleration; white-jerk process
// noise of spectral density q). The noise models come from the measurements themselves:
//  - measurement variance: the angle's stated sd (JointAngle::sd_rad, floored at
//    min_angle_sd_rad) times a factor kappa, the running mean of (third difference of the
//    angle)^2 over its variance as the stated sds predict it (v0 + 9 v1 + 9 v2 + v3). For
//    the motions of a robot the third difference over 10 ms is all noise (a jerk of
//    10^4 deg/s^3 moves it by 0.01 deg), so kappa is 1 when the stated sd is right and
//    corrects it when it is not; it is kept within [1/4, 400] (sd x 0.5 .. x 20);
//  - process noise: q = jerk_psd_rad2_s5 x lambda, lambda driven by the running mean of the
//    normalised innovation squared (NIS, 1 for a consistent filter) so that fast motions
//    widen the filter and slow ones narrow it; lambda within [1e-2, 1e3].
// A consistent filter states an sd that covers its error; the adaptation keeps it so when
// either noise model is off (tests/kinematics/test_joint_rates.cpp).
//
// A joint not valid in a frame keeps its state; one unobserved for longer than max_gap_s
// restarts from its next angle; an angle not newer than the joint's last is skipped
// (counted). Rates are valid from the warmup_observations-th observation after a restart.
// Innovations are wrapped to
// (-pi, pi] (ball angles wrap; the state is continuous and never wrapped).
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "core/expected.h"
#include "core/joint_type.h"
#include "kinematics/joint_angles.h"

namespace mocap::kinematics {

struct RateFilterConfig {
  double max_gap_s = 0.1;            // longer without an angle: the joint's filter restarts
  double jerk_psd_rad2_s5 = 30.0;    // base white-jerk density (1e5 deg^2/s^5)
  double min_angle_sd_rad = 3.0e-4;  // floor of the stated angle sd (0.017 deg)
  int warmup_observations = 3;       // observations after a restart before rates are valid
};

// Counters of the filter (never reset but by reset()).
struct RateFilterCounters {
  std::uint64_t restarts = 0;        // joint filters (re)started: first sight or a gap
  std::uint64_t time_reversals = 0;  // angles not newer than the joint's last (skipped)
};

class JointRateFilter {
 public:
  // types: one per joint, model order (hinges have one degree of freedom, balls three).
  // Errors name the key of the configuration that is out of range.
  static Expected<JointRateFilter> create(const RateFilterConfig& config,
                                          const std::vector<JointType>& types);

  // Fills rate_valid, rate_rad_s and rate_sd_rad_s of every joint of `angles` from its
  // angles at capture time t_ns (CLOCK_MONOTONIC or any clock in ns). `angles` must have
  // one entry per joint of create() (else nothing is written and false is returned).
  bool update(std::int64_t t_ns, JointAngles& angles) noexcept;
  void reset() noexcept;

  std::size_t num_joints() const noexcept { return joints_.size(); }
  const RateFilterConfig& config() const noexcept { return config_; }
  const RateFilterCounters& counters() const noexcept { return counters_; }

 private:
  struct Dof {
    std::array<double, 3> x{};  // angle (rad, continuous), rate (rad/s), acceleration
    std::array<double, 6> P{};  // covariance, upper triangle: 00 01 02 11 12 22
    std::array<double, 4> z{};  // the last observations (continuous), oldest first
    std::array<double, 4> v{};  // their stated variances
    double nis_mean = 1.0;      // running mean of the normalised innovation squared
    double lambda = 1.0;        // process-noise scale
    double kappa = 1.0;         // measurement-noise scale
  };
  struct Joint {
    int dofs = 3;
    bool active = false;   // a filter runs (observed within max_gap_s)
    int observations = 0;  // since the last restart
    std::int64_t t_last_ns = 0;
    std::array<std::int64_t, 4> t_hist{};  // times of Dof::z (equal spacing check)
    int hist = 0;                          // valid entries of z/v/t_hist
    std::array<Dof, 3> dof{};
  };

  void restart(Joint& j, const JointAngle& a, std::int64_t t_ns) noexcept;
  void step(Joint& j, JointAngle& a, std::int64_t t_ns) noexcept;
  double stated_variance(const JointAngle& a, int k) const noexcept;

  RateFilterConfig config_;
  std::vector<Joint> joints_;
  RateFilterCounters counters_;
};

}  // namespace mocap::kinematics
