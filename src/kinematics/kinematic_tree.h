// Design: the joint topology as a forest of bodies (set-up only). Every body is the child
// of at most one joint; cycles are rejected. Roots are bodies that appear in a joint but
// are nobody's child. `joint_order` lists joints parents-first, so a pass over it can
// compose poses from the roots outwards; `path_to(body)` lists the joints from the root
// down to that body.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "core/expected.h"
#include "formats/joints_yaml.h"

namespace mocap::kinematics {

struct KinematicTree {
  std::vector<int> parent_joint;  // per body: the joint whose child it is, or -1
  std::vector<int> parent_body;   // per body: that joint's parent body, or -1
  std::vector<int> roots;         // bodies used by a joint and child of none
  std::vector<int> joint_order;   // joints, parents before children
  std::vector<bool> used;         // per body: appears in some joint

  int root_of(int body) const noexcept;
  std::vector<int> path_to(const JointModel& model, int body) const;  // root -> body
};

// num_bodies: size of the TargetSet. `file` names the joints file in messages.
Expected<KinematicTree> build_tree(const JointModel& model, std::size_t num_bodies,
                                   const std::string& file = "joints.yaml");

}  // namespace mocap::kinematics
