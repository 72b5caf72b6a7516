// Design: causal body velocities, estimated live on the identify thread from each frame's
// body poses (docs/kinematics.md, "Body velocities"): the linear velocity of the body's
// origin and the angular velocity, both in the world frame, with their standard
// deviations. Immutable configuration plus preallocated per-body state sized by
// create(); update() is noexcept and allocation-free.
//
// Six constant-acceleration filters per body (ca_filter.h, the joint rates' filter):
//  - three on the origin's coordinates t_world_body (mm);
//  - three on the world-frame rotation path Z: each frame adds the rotation vector of
//    R_now R_last^T (rad), so that dZ/dt is the world angular velocity and Z is
//    continuous through any number of turns. The increment of a step is below pi while the
//    body turns slower than pi per max_gap_s (1800 deg/s at the default 100 ms).
// Measurement noise: the caller states each pose's position and rotation sd (from the
// point noise, the markers matched and the target's size; track/frame_processor.cpp);
// the filters correct them by the measured third differences (kappa) as for joints.
// A body not found keeps its state; one unseen for longer than max_gap_s restarts; a pose
// not newer than the body's last is skipped (counted). Velocities are valid from the
// warmup_observations-th pose after a restart.
#pragma once

#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include "core/expected.h"
#include "core/types.h"
#include "kinematics/ca_filter.h"
#include "kinematics/joint_rates.h"

namespace mocap::kinematics {

// One body's pose in a frame, with its stated noise.
struct BodyMeasurement {
  bool found = false;
  Iso3 T_world_body = Iso3::Identity();
  double position_sd_mm = 0.0;   // sd of each coordinate of the origin
  double rotation_sd_rad = 0.0;  // sd of each component of the rotation error
};

struct BodyRate {
  bool valid = false;  // the body was found in this frame and its filter warmed up
  Vec3 v_world_mm_s = Vec3::Zero();
  Vec3 w_world_rad_s = Vec3::Zero();
  Vec3 v_sd_mm_s = Vec3::Zero();
  Vec3 w_sd_rad_s = Vec3::Zero();
};

class BodyRateFilter {
 public:
  // Errors name the key of the configuration that is out of range.
  static Expected<BodyRateFilter> create(const RateFilterConfig& config, std::size_t bodies);

  std::vector<BodyRate> make_output() const { return std::vector<BodyRate>(bodies_.size()); }

  // Writes out[b] for every body from its pose at capture time t_ns. Both spans must have
  // one entry per body of create() (else nothing is written and false is returned).
  bool update(std::int64_t t_ns, std::span<const BodyMeasurement> bodies,
              std::span<BodyRate> out) noexcept;
  void reset() noexcept;

  std::size_t num_bodies() const noexcept { return bodies_.size(); }
  const RateFilterCounters& counters() const noexcept { return counters_; }

 private:
  struct Body {
    CaClock clock;
    std::array<CaAxis, 6> axis{};  // x, y, z of the origin; x, y, z of the rotation path
    Quat q_last = Quat::Identity();
    Vec3 z_rot_rad = Vec3::Zero();  // the rotation path Z
  };

  void restart(Body& body, const BodyMeasurement& m, std::int64_t t_ns) noexcept;
  void step(Body& body, const BodyMeasurement& m, std::int64_t t_ns, BodyRate& out) noexcept;
  double position_variance(const BodyMeasurement& m) const noexcept;
  double rotation_variance(const BodyMeasurement& m) const noexcept;

  RateFilterConfig config_;
  std::vector<Body> bodies_;
  RateFilterCounters counters_;
};

}  // namespace mocap::kinematics
