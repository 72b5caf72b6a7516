// Design: accuracy of the tracker's causal joint rates (angles.csv da0..da2 and their sds,
// docs/kinematics.md "Joint rates") against ground truth (the simulator's gt/angles.csv or
// any angles.csv of the true motion). The true rate of a frame is the central difference
// of the true angles of its neighbours (both present, equally spaced within 10 %), wrapped
// to +-180 deg: its own error (jerk x dt^2 / 6) is ~0.1 deg/s for a robot's motions at
// 100 fps, far below the filter's. Each degree of freedom of a joint counts as one sample
// (a ball joint three per frame, a hinge one).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "formats/csv_outputs.h"

namespace mocap {

struct JointRateError {
  std::string joint;
  JointType type = JointType::kBall;
  std::int64_t samples = 0;  // degrees of freedom x frames with a rate and a true rate
  double rms_deg_s = 0.0;    // RMS of (measured - true) rate
  double max_deg_s = 0.0;
  double rms_sd_deg_s = 0.0;  // RMS of the stated sd over the same samples
  double sd_ratio = 0.0;      // rms_sd / rms: 1 for a consistent filter
};

// Joints in order of first appearance in `truth`; `all` (optional): every sample pooled.
std::vector<JointRateError> rate_errors(const std::vector<AngleRow>& truth,
                                        const std::vector<AngleRow>& measured,
                                        JointRateError* all = nullptr);

}  // namespace mocap
