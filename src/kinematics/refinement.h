// Design: the joint non-linear refinement of all joints of the forest together (Ceres),
// started from the linear estimates, minimising the marker residuals
//   r = T_world_root(f) * prod_joints T_parent_child(joint params, q_f) * X_body - X_meas
// with a Huber loss per marker. Parameters (docs/kinematics.md):
//  - per frame: root pose (unit quaternion on ceres::QuaternionManifold + translation),
//    ball rotation (unit quaternion), hinge angle theta (1 scalar);
//  - per ball joint: c_parent, c_child (mm);
//  - per hinge: axis_parent, axis_child (ceres::SphereManifold<3>), c_parent (3), and
//    c_child = c_child0 + B u (u in R^2, B spanning the plane normal to the initial child
//    axis) which removes the gauge of sliding both points along the axis. The relative
//    rotation is R = F_p Rz(theta) F_c^T, F = [x y a] with x the fixed reference vector
//    (initial c_x of frame C) made orthogonal to a: a maps to a exactly.
// After the solve the hinge point is moved along the axis to the minimum-norm position
// (c_p.a_p + c_c.a_c = 0), the convention of the linear estimate. The covariance of the
// joint parameters (ceres::Covariance, SPARSE_QR) is scaled by the a-posteriori variance
// factor sum(r^2) / (m - n) and written as standard deviations into JointSpec::extra.
#pragma once

#include <vector>

#include "core/expected.h"
#include "formats/joints_yaml.h"
#include "formats/targets_yaml.h"
#include "kinematics/calibrate.h"
#include "kinematics/kinematic_tree.h"

namespace mocap::kinematics {

struct RefinementOutput {
  JointModel model;                  // refined parameters + extras
  std::vector<BodyResidual> bodies;  // per used body
  std::vector<double> joint_rms_mm;  // per joint: child body's RMS
  int frames = 0;
  int iterations = 0;
  double seconds = 0.0;
  std::string summary;
  std::vector<std::string> warnings;
};

// `initial`: every joint calibrated (linear estimates). `frames`: indices into input.
Expected<RefinementOutput> refine_joints(const TargetSet& targets, const JointModel& initial,
                                         const KinematicTree& tree, const CalibrationInput& input,
                                         const std::vector<int>& frames,
                                         const CalibrationOptions& options);

}  // namespace mocap::kinematics
