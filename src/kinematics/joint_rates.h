// Design: causal joint rates (the velocities of a0..a2) and their standard deviations,
// estimated live on the identify thread from the angles of each frame (docs/kinematics.md,
// "Joint rates"). Immutable configuration plus preallocated per-degree-of-freedom state,
// sized once by create(); update() is noexcept and allocation-free.
//
// Each degree of freedom (a ball joint's three angles, a hinge's one) has its own
// constant-acceleration Kalman filter with adaptive noise (ca_filter.h): the measurement
// variance is the angle's stated sd (JointAngle::sd_rad, floored at min_angle_sd_rad)
// corrected by the measured third differences, the process noise jerk_psd_rad2_s5 scaled
// by the innovations. A consistent filter states an sd that covers its error; the
// adaptation keeps it so when either noise model is off
// (tests/kinematics/test_joint_rates.cpp).
//
// A joint not valid in a frame keeps its state; one unobserved for longer than max_gap_s
// restarts from its next angle; an angle not newer than the joint's last is skipped
// (counted). Rates are valid from the warmup_observations-th observation after a restart.
// Innovations are wrapped to (-pi, pi] (ball angles wrap; the state is continuous and
// never wrapped).
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "core/expected.h"
#include "core/joint_type.h"
#include "kinematics/ca_filter.h"
#include "kinematics/joint_angles.h"

namespace mocap::kinematics {

struct RateFilterConfig {
  double max_gap_s = 0.1;            // longer without an angle: the joint's filter restarts
  double jerk_psd_rad2_s5 = 30.0;    // base white-jerk density (1e5 deg^2/s^5)
  double min_angle_sd_rad = 3.0e-4;  // floor of the stated angle sd (0.017 deg)
  int warmup_observations = 3;       // observations after a restart before rates are valid
  // Body velocities (body_rates.h): the base white-jerk density of a body origin's
  // coordinates (jerk_psd_rad2_s5 at a 300 mm lever) and the floor of a position's stated sd.
  double body_jerk_psd_mm2_s5 = 3.0e6;
  double min_position_sd_mm = 0.005;
};

// Every key in range (joint and body filters alike); the error names the configuration key.
Expected<void> check_rate_config(const RateFilterConfig& config);

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
  struct Joint {
    int dofs = 3;
    CaClock clock;
    std::array<CaAxis, 3> dof{};
  };

  void restart(Joint& j, const JointAngle& a, std::int64_t t_ns) noexcept;
  void step(Joint& j, JointAngle& a, std::int64_t t_ns) noexcept;
  double stated_variance(const JointAngle& a, int k) const noexcept;

  RateFilterConfig config_;
  std::vector<Joint> joints_;
  RateFilterCounters counters_;
};

}  // namespace mocap::kinematics
