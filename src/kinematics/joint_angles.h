// Design: real-time joint angles from tracked body poses (the paper's Section 4).
// Immutable model (hinge frames C precomputed at create()) plus a small per-joint state
// (hinge unwrapping). compute() is noexcept and allocation-free; the output buffer is
// sized once by make_output().
// Conventions (docs/kinematics.md; the spec's angles.csv):
//  - every joint: quaternion of R_rel = R_parent^T * R_child (child -> parent), qw >= 0;
//  - ball: a0..a2 = intrinsic X-Y'-Z'' Euler angles of R_rel (core/rotation.h), i.e. the
//    body frames are the reference, no extra joint frame; URDF's three revolutes match;
//  - hinge: a0 = angle about axis_parent of the child's frame-C x axis, measured from the
//    parent's frame-C x axis, atan2 in the plane normal to the axis, unwrapped over time
//    (continuous across +-pi; the first valid frame after create()/reset() is in (-pi, pi]);
//    a1 = a2 = 0. Invalid frames (a body not found) keep the unwrapping state.
#pragma once

#include <array>
#include <cstddef>
#include <vector>

#include "client/joints_message.h"
#include "core/expected.h"
#include "core/types.h"
#include "formats/joints_yaml.h"

namespace mocap::kinematics {

struct BodyPoseView {
  bool found = false;
  Iso3 T_world_body = Iso3::Identity();
};

struct JointAngle {
  bool valid = false;  // both bodies known (found, or solved through the kinematic chain)
  JointType type = JointType::kBall;
  double a0 = 0.0, a1 = 0.0, a2 = 0.0;     // rad
  Quat q_parent_child = Quat::Identity();  // R_parent^T R_child, qw >= 0
  // How the angles were obtained (the public enum of the message) and their standard
  // deviations (rad; hinge: a0 only). compute() sets kPoses and 0; chain tracking
  // (track/chain_solver.h) fills both.
  client::SolvedBy solved_by = client::SolvedBy::kNone;
  std::array<double, 3> sd_rad{};
  // The causal rates of a0..a2 and their standard deviations (rad/s; hinge: index 0), set
  // by JointRateFilter (joint_rates.h); rate_valid is false while none is known.
  bool rate_valid = false;
  std::array<double, 3> rate_rad_s{};
  std::array<double, 3> rate_sd_rad_s{};
};

struct JointAngles {
  std::vector<JointAngle> joints;  // model order
  int valid_count = 0;
};

class JointAngleSolver {
 public:
  // Every joint must be calibrated with finite parameters (hinges: non-zero axes);
  // body indices must be < num_bodies.
  static Expected<JointAngleSolver> create(const JointModel& model, std::size_t num_bodies);

  JointAngles make_output() const;  // sized for compute()

  // poses_by_body_index: num_bodies entries. Returns false (and writes nothing) when
  // `out` was not sized by make_output().
  bool compute(const BodyPoseView* poses_by_body_index, JointAngles& out) noexcept;
  void reset() noexcept;

  std::size_t num_joints() const noexcept { return joints_.size(); }
  std::size_t num_bodies() const noexcept { return num_bodies_; }

 private:
  struct Joint {
    JointType type = JointType::kBall;
    int parent = -1, child = -1;
    Mat3 R_parent_C = Mat3::Identity();  // hinge: frame C rotation in the parent
    Vec3 x_child_C = Vec3::UnitX();      // hinge: child's frame-C x axis (child frame)
    // state
    bool has_previous = false;
    double previous_rad = 0.0;  // last unwrapped hinge angle
  };
  std::vector<Joint> joints_;
  std::size_t num_bodies_ = 0;
};

// The hinge angle of a relative rotation, wrapped to (-pi, pi] (no state).
double hinge_angle(const Mat3& R_parent_C, const Vec3& x_child_C,
                   const Mat3& R_parent_child) noexcept;

}  // namespace mocap::kinematics
