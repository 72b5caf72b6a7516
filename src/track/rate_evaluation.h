// Design: accuracy of the tracker's causal joint rates (angles.csv da0..da2 and their sds,
// docs/kinematics.md "Joint rates") against ground truth (the simulator's gt/angles.csv or
// any angles.csv of the true motion). The true rate of a frame is the central difference
// of the true angles of its neighbours (both present, equally spaced within 10 %), wrapped
// to +-180 deg: its own error (jerk x dt^2 / 6) is ~0.1 deg/s for a robot's motions at
// 100 fps, far below the filter's. Each degree of freedom of a joint counts as one sample
// (a ball joint three per frame, a hinge one).
// Body velocities (poses.csv vx..sd_wz) likewise against the central differences of the
// true poses: the origin's displacement, and the rotation vector of R_after R_before^T
// (world frame); each coordinate counts as one sample.
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

// Unit-free error statistics of one rate.
struct RateStats {
  std::int64_t samples = 0;
  double rms = 0.0;
  double max = 0.0;
  double rms_sd = 0.0;    // RMS of the stated sd over the same samples
  double sd_ratio = 0.0;  // rms_sd / rms: 1 for a consistent filter
};

struct BodyRateError {
  std::string body;
  RateStats linear_mm_s;    // velocity of the body origin
  RateStats angular_deg_s;  // angular velocity
};

// Bodies in order of first appearance in `truth`; `all` (optional): every sample pooled.
std::vector<BodyRateError> body_rate_errors(const std::vector<PoseRow>& truth,
                                            const std::vector<PoseRow>& measured,
                                            BodyRateError* all = nullptr);

// Joints in order of first appearance in `truth`; `all` (optional): every sample pooled.
std::vector<JointRateError> rate_errors(const std::vector<AngleRow>& truth,
                                        const std::vector<AngleRow>& measured,
                                        JointRateError* all = nullptr);

}  // namespace mocap
