// Design: see kinematic_tree.h.
#include "kinematics/kinematic_tree.h"

#include <algorithm>

namespace mocap::kinematics {

int KinematicTree::root_of(int body) const noexcept {
  // The forest is acyclic (checked by build_tree); bounded loop for safety.
  for (std::size_t guard = 0; guard <= parent_joint.size(); ++guard) {
    if (parent_joint[static_cast<std::size_t>(body)] < 0) return body;
    body = parent_body[static_cast<std::size_t>(body)];
  }
  return -1;
}

std::vector<int> KinematicTree::path_to(const JointModel& model, int body) const {
  std::vector<int> joints;
  while (body >= 0 && parent_joint[static_cast<std::size_t>(body)] >= 0) {
    const int j = parent_joint[static_cast<std::size_t>(body)];
    joints.push_back(j);
    body = model.joints[static_cast<std::size_t>(j)].parent_index;
  }
  std::reverse(joints.begin(), joints.end());
  return joints;
}

Expected<KinematicTree> build_tree(const JointModel& model, std::size_t num_bodies,
                                   const std::string& file) {
  KinematicTree tree;
  tree.parent_joint.assign(num_bodies, -1);
  tree.parent_body.assign(num_bodies, -1);
  tree.used.assign(num_bodies, false);
  if (model.joints.empty()) return make_error(file, "joints", "no joints");
  const int nb = static_cast<int>(num_bodies);
  for (std::size_t j = 0; j < model.joints.size(); ++j) {
    const JointSpec& s = model.joints[j];
    const std::string where = "joints." + s.name;
    if (s.parent_index < 0 || s.parent_index >= nb || s.child_index < 0 || s.child_index >= nb) {
      return make_error(file, where,
                        "parent/child body index out of range (" + std::to_string(s.parent_index) +
                            ", " + std::to_string(s.child_index) + " for " + std::to_string(nb) +
                            " bodies)");
    }
    if (s.parent_index == s.child_index) {
      return make_error(file, where, "parent and child are the same body");
    }
    auto& pj = tree.parent_joint[static_cast<std::size_t>(s.child_index)];
    if (pj >= 0) {
      return make_error(file, where,
                        "body '" + s.child + "' is already the child of joint '" +
                            model.joints[static_cast<std::size_t>(pj)].name + "'");
    }
    pj = static_cast<int>(j);
    tree.parent_body[static_cast<std::size_t>(s.child_index)] = s.parent_index;
    tree.used[static_cast<std::size_t>(s.parent_index)] = true;
    tree.used[static_cast<std::size_t>(s.child_index)] = true;
  }
  // Depth of every body; a walk longer than the body count means a cycle.
  std::vector<int> depth(num_bodies, 0);
  for (int b = 0; b < nb; ++b) {
    int cur = b, d = 0;
    while (tree.parent_body[static_cast<std::size_t>(cur)] >= 0) {
      cur = tree.parent_body[static_cast<std::size_t>(cur)];
      if (++d > nb) {
        const int j = tree.parent_joint[static_cast<std::size_t>(b)];
        return make_error(file, "joints." + model.joints[static_cast<std::size_t>(j)].name,
                          "the joints form a cycle");
      }
    }
    depth[static_cast<std::size_t>(b)] = d;
    if (tree.used[static_cast<std::size_t>(b)] && d == 0) tree.roots.push_back(b);
  }
  for (std::size_t j = 0; j < model.joints.size(); ++j)
    tree.joint_order.push_back(static_cast<int>(j));
  std::stable_sort(tree.joint_order.begin(), tree.joint_order.end(), [&](int a, int b) {
    return depth[static_cast<std::size_t>(model.joints[static_cast<std::size_t>(a)].child_index)] <
           depth[static_cast<std::size_t>(model.joints[static_cast<std::size_t>(b)].child_index)];
  });
  return tree;
}

}  // namespace mocap::kinematics
