// Design: the immutable kinematic-chain model of chain tracking (chain_solver.h): the
// calibrated joints of model.yaml arranged as a forest of bodies (every body the child
// of at most one joint), parents before children, with each child's marker target
// expressed about its joint (the lever vectors the solver rotates). Built once at setup
// from the TargetSet and the calibrated JointModel; never changes afterwards.
//
// Parametrisation of a joint's relative rotation R_parent_child (child -> parent):
//  - ball: any rotation; the child's centre c_child maps onto the parent's c_parent;
//  - hinge: R = Rot(axis_parent, theta) * R_zero, where R_zero maps axis_child onto
//    axis_parent (built from the two hinge frames C of kinematics/joint_frame.h).
// In both cases T_parent_child = (R, c_parent - R c_child).
// A joint whose child already has a parent joint (a loop or a second parent) cannot be
// chain-tracked: it is left out of the chain (listed in warnings()) and its angle comes
// from the two poses only, as before.
#pragma once

#include <array>
#include <string>
#include <vector>

#include "core/expected.h"
#include "core/types.h"
#include "formats/joints_yaml.h"
#include "formats/targets_yaml.h"
#include "identify/identify_types.h"

namespace mocap {

// Degrees of freedom of a chain: 3 per ball joint, 1 per hinge; a model of kMaxBodies
// bodies has at most kMaxBodies chain joints (96 DOF). The solver's dense matrices are
// kMaxChainDof^2 (chain_solver.h: on the heap).
inline constexpr int kMaxChainDof = 3 * kMaxBodies;

struct ChainJoint {
  JointType type = JointType::kBall;
  int parent = -1;  // body indices (TargetSet order)
  int child = -1;
  int dof = 3;      // 3 (ball) or 1 (hinge)
  Vec3 c_parent = Vec3::Zero();    // joint centre in the parent's frame (mm)
  Vec3 c_child = Vec3::Zero();     // the same point in the child's frame (mm)
  Vec3 axis_parent = Vec3::UnitZ();  // hinge: unit axis in the parent's frame
  Vec3 axis_child = Vec3::UnitZ();   // hinge: unit axis in the child's frame
  Mat3 R_zero = Mat3::Identity();    // hinge: R_parent_child at theta = 0
  bool in_chain = false;             // false: loop / second parent, poses only
};

class ChainModel {
 public:
  // Every joint must be calibrated (JointAngleSolver's checks); at most kMaxBodies bodies
  // of at most kMaxMarkers markers.
  static Expected<ChainModel> create(const JointModel& model, const TargetSet& targets);

  int joint_count() const noexcept { return static_cast<int>(joints_.size()); }
  int body_count() const noexcept { return static_cast<int>(markers_body_.size()); }
  const ChainJoint& joint(int j) const noexcept { return joints_[static_cast<std::size_t>(j)]; }
  // Joint indices, every chain joint after the chain joint of its parent body.
  const std::vector<int>& order() const noexcept { return order_; }
  // The chain joint whose child is `body`, or -1 (a root, or not in a chain).
  int joint_into(int body) const noexcept { return joint_into_[static_cast<std::size_t>(body)]; }
  const std::vector<Vec3>& markers(int body) const noexcept {
    return markers_body_[static_cast<std::size_t>(body)];
  }
  const std::vector<std::string>& warnings() const noexcept { return warnings_; }

  // R_parent_child of a hinge at angle theta (rad, the parametrisation above).
  Mat3 hinge_rotation(int j, double theta) const noexcept;
  // T_parent_child for a relative rotation R.
  Iso3 parent_child(int j, const Mat3& R_parent_child) const noexcept;

 private:
  std::vector<ChainJoint> joints_;
  std::vector<int> order_;
  std::vector<int> joint_into_;
  std::vector<std::vector<Vec3>> markers_body_;
  std::vector<std::string> warnings_;
};

}  // namespace mocap
