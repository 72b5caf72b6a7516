// Design: the body velocities of every frame (kinematics/body_rates.h) fed from the
// identified poses, with each pose's noise stated from the camera model's point noise
// (identification.point_sigma_mm), the markers matched and the target's geometry:
//  - rotation: sigma^2 J^-1 with J = sum_i (|p_i|^2 I - p_i p_i^T) over the target's
//    markers about their centroid, scaled by n/m for m of n markers matched; the stated sd
//    is the root mean of its diagonal;
//  - origin: sigma^2/m for the centroid plus the rotation error times the lever from the
//    centroid to the body origin.
// The filter corrects both by the measured third differences (kinematics/ca_filter.h).
// Immutable geometry plus preallocated workspace; update() is noexcept, allocation-free.
#pragma once

#include <span>
#include <vector>

#include "core/expected.h"
#include "formats/targets_yaml.h"
#include "identify/identify_types.h"
#include "kinematics/body_rates.h"

namespace mocap {

class BodyMotion {
 public:
  static Expected<BodyMotion> create(const TargetSet& targets, double point_sigma_mm,
                                     const kinematics::RateFilterConfig& config);

  std::vector<kinematics::BodyRate> make_output() const { return filter_.make_output(); }
  // out: one entry per target (make_output()).
  bool update(std::int64_t t_ns, const BodyPoses& poses,
              std::span<kinematics::BodyRate> out) noexcept;
  void reset() noexcept { filter_.reset(); }
  const kinematics::RateFilterCounters& counters() const noexcept { return filter_.counters(); }

 private:
  struct Geometry {
    int markers = 0;                 // n, the target's markers
    double rotation_var_rad2 = 0.0;  // per component, all n markers matched, sigma = 1 mm
    double lever_mm = 0.0;           // |centroid| in the body frame
  };
  explicit BodyMotion(kinematics::BodyRateFilter filter) : filter_(std::move(filter)) {}

  kinematics::BodyRateFilter filter_;
  std::vector<Geometry> geometry_;
  double sigma_mm_ = 0.2;
  std::vector<kinematics::BodyMeasurement> measured_;  // workspace
};

}  // namespace mocap
