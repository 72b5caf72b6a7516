// Design: the paper's error evaluation (Section 3.4, Table 1, the calibration errors of
// Section 3.2) as pure functions of model files, pose and angle rows and the simulator's
// hold/move segments, so that `mocap evaluate` and bench/evaluation/run_evaluation.sh
// compute every number of docs/evaluation.md here, tested on hand-made inputs
// (tests/track/test_evaluation.cpp). Offline only; nothing here runs per frame.
//
// Definitions (docs/evaluation.md):
//  - calibration: per joint, |c_est - c_true| in the parent and in the child frame; for
//    hinges also the axis direction error (sign-free angle, degrees) and the axis
//    position error = distance of the true centre from the estimated axis line (mm).
//  - Table 1A (distance): for each pair of hold segments separated by one move segment,
//    each body's mean position in both holds; error = measured distance - true distance
//    (|t_b - t_a| of the segments' robot translations); RMSE per body.
//  - Table 1B (precision): per joint, over frames with both bodies found: the RMS
//    deviation from the mean of the parent->child translation (mm, 3D), of the relative
//    rotation (geodesic angle from the quaternion mean, deg) and of the joint angle
//    (hinge: angle; ball: sqrt of the mean variance of the three Euler angles, deg).
//  - angle errors: per joint and frame, ball = geodesic angle of q_true^-1 q_meas,
//    hinge = a0_meas - a0_true; RMS, max, mean (bias), RMS after removing the mean, and
//    the count of gross errors (> 1 deg) with the RMS over the remaining frames.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "core/expected.h"
#include "core/types.h"
#include "formats/csv_outputs.h"
#include "formats/joints_yaml.h"

namespace mocap {

struct CalibrationError {
  std::string joint;
  JointType type = JointType::kBall;
  double center_parent_mm = 0.0;
  double center_child_mm = 0.0;
  double axis_parent_deg = 0.0;          // hinge only
  double axis_child_deg = 0.0;           // hinge only
  double axis_position_parent_mm = 0.0;  // hinge only: true centre to estimated axis line
  double axis_position_child_mm = 0.0;
};

// Joints are matched by name; every joint of `truth` must be in `estimate` with the same
// type and both must be calibrated.
Expected<std::vector<CalibrationError>> calibration_errors(const JointModel& estimate,
                                                           const JointModel& truth);

struct Segment {
  int index = 0;
  bool hold = false;  // hold | move
  std::int64_t first_frame = 0;
  std::int64_t last_frame = 0;
  Vec3 t_robot_mm = Vec3::Zero();  // holds: the robot's translation
};

// Reads gt/segments.csv (segment,kind,first_frame,last_frame,tx,ty,tz).
Expected<std::vector<Segment>> read_segments_csv(const std::string& path);

struct DistancePair {
  int hold_a = 0, hold_b = 0;  // segment indices
  double true_mm = 0.0;
  double measured_mm = 0.0;  // NaN when the body was not found in one of the holds
};

struct BodyDistanceError {
  std::string body;
  std::vector<DistancePair> pairs;
  int pairs_used = 0;
  double rmse_mm = 0.0;
  double mean_error_mm = 0.0;  // signed: measured - true
  double max_abs_error_mm = 0.0;
};

// Table 1A. Bodies in order of first appearance in `poses`.
std::vector<BodyDistanceError> distance_errors(const std::vector<PoseRow>& poses,
                                               const std::vector<Segment>& segments);

struct JointPrecision {
  std::string joint;
  JointType type = JointType::kBall;
  std::int64_t frames = 0;
  double translation_std_mm = 0.0;
  double rotation_std_deg = 0.0;
  double angle_std_deg = 0.0;
};

// Table 1B: relative transforms from `poses` (parent/child names from `model`), joint
// angles from `angles` (rows of the model's joints).
std::vector<JointPrecision> joint_precision(const JointModel& model,
                                            const std::vector<PoseRow>& poses,
                                            const std::vector<AngleRow>& angles);

struct JointAngleError {
  std::string joint;
  JointType type = JointType::kBall;
  std::int64_t frames = 0;
  double rms_deg = 0.0;
  double max_deg = 0.0;
  double mean_deg = 0.0;          // hinge: signed bias; ball: mean geodesic angle
  double rms_debiased_deg = 0.0;  // hinge: RMS about the mean; ball: = rms_deg
  // Gross errors (|error| > kGrossAngleErrorDeg: wrong identities, flipped poses) apart
  // from the precision: their count and the RMS over the other frames.
  std::int64_t gross = 0;
  double rms_without_gross_deg = 0.0;
};

inline constexpr double kGrossAngleErrorDeg = 1.0;

struct AngleErrorSample {
  std::int64_t frame = 0;
  std::int64_t timestamp_ns = 0;
  std::string joint;
  double error_deg = 0.0;  // as defined above (hinge signed)
};

// Matches rows by (frame, joint); joints in order of first appearance in `truth`.
std::vector<JointAngleError> angle_errors(const std::vector<AngleRow>& truth,
                                          const std::vector<AngleRow>& measured,
                                          std::vector<AngleErrorSample>* series = nullptr);

}  // namespace mocap
