// Design: joint calibration of a whole kinematic forest from tracked frames (set-up /
// offline code; allocates, returns Expected). Steps, each documented in
// docs/kinematics.md:
//  1. topology check (kinematic_tree.h) and input validation;
//  2. per joint, the linear estimate (Eq. 2 ball / rank-5 hinge) from the frames in which
//     both bodies were found, with the degeneracy checks of linear_estimation.h;
//  3. optionally the joint Ceres refinement of all joints together on the marker
//     residuals (refinement.h), with residual RMS per body and joint and the covariance of
//     the joint parameters written into JointSpec::extra.
// Input (filled by the tracker): per frame, per body of the TargetSet (same indices): the
// found flag, T_world_body, and the matched markers (index in the body's target, measured
// world position). Bodies that are not found may leave `markers` empty.
#pragma once

#include <string>
#include <vector>

#include "core/expected.h"
#include "core/types.h"
#include "formats/joints_yaml.h"
#include "formats/targets_yaml.h"
#include "kinematics/linear_estimation.h"

namespace mocap::kinematics {

struct MarkerObservation {
  int marker_index = -1;           // index into MarkerTarget::markers_body
  Vec3 X_world_mm = Vec3::Zero();  // measured (triangulated) position
};

struct BodyObservation {
  bool found = false;
  Iso3 T_world_body = Iso3::Identity();
  std::vector<MarkerObservation> markers;
};

struct CalibrationFrame {
  std::vector<BodyObservation> bodies;  // indexed like TargetSet::bodies
};

struct CalibrationInput {
  std::vector<CalibrationFrame> frames;
};

struct CalibrationOptions {
  LinearOptions linear;
  bool refine = true;      // Ceres refinement after the linear estimates
  bool covariance = true;  // parameter uncertainty (needs refine)
  double huber_mm = 1.0;   // robust loss scale of the marker residuals
  int max_frames = 400;    // evenly subsample usable frames beyond this
  int max_iterations = 100;
  double min_axis_lever_mm = 1.0;  // hinge axis closer to a body origin: warning (frame C)
};

struct BodyResidual {
  std::string body;
  int observations = 0;  // marker observations used
  double rms_mm = 0.0;   // sqrt(mean |predicted - measured|^2)
  double max_mm = 0.0;
};

struct JointReport {
  std::string joint;
  LinearDiagnostics linear;
  int frames_used = 0;           // frames with both bodies found (linear step)
  double residual_rms_mm = 0.0;  // refined marker RMS of the child body (0 if no refine)
};

struct CalibrationReport {
  std::vector<JointReport> joints;   // in model order
  std::vector<BodyResidual> bodies;  // bodies used by the refinement
  int refine_frames = 0;
  int refine_iterations = 0;
  double refine_seconds = 0.0;
  std::string solver_summary;         // Ceres BriefReport
  std::vector<std::string> warnings;  // one line each, with numbers
};

struct CalibrationResult {
  JointModel model;  // calibrated (all joints calibrated = true), extras filled
  CalibrationReport report;
};

// `topology`: joints with parent_index/child_index set (as load_joints does).
Expected<CalibrationResult> calibrate_joints(const TargetSet& targets, const JointModel& topology,
                                             const CalibrationInput& input,
                                             const CalibrationOptions& options = {});

// Human-readable multi-line summary (per joint: parameters, linear singular values,
// residual and uncertainty extras; per body residuals; warnings) for the CLI and logs.
std::string format_report(const CalibrationResult& result);

}  // namespace mocap::kinematics
