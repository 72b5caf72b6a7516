// Design: see chain_model.h.
#include "track/chain_model.h"

#include "kinematics/joint_frame.h"

namespace mocap {

Expected<ChainModel> ChainModel::create(const JointModel& model, const TargetSet& targets) {
  ChainModel m;
  const int nb = static_cast<int>(targets.bodies.size());
  if (nb > kMaxBodies)
    return make_error("targets.yaml", "bodies",
                      std::to_string(nb) + " bodies, chain tracking supports at most " +
                          std::to_string(kMaxBodies));
  for (const MarkerTarget& t : targets.bodies) {
    if (static_cast<int>(t.markers_body.size()) > kMaxMarkers)
      return make_error("targets.yaml", "bodies." + t.name,
                        "more than " + std::to_string(kMaxMarkers) + " markers");
    m.markers_body_.push_back(t.markers_body);
  }
  m.joint_into_.assign(static_cast<std::size_t>(nb), -1);
  for (const JointSpec& s : model.joints) {
    const std::string where = "joints." + s.name;
    if (!s.calibrated) return make_error("model.yaml", where, "joint is not calibrated");
    if (s.parent_index < 0 || s.parent_index >= nb || s.child_index < 0 ||
        s.child_index >= nb || s.parent_index == s.child_index)
      return make_error("model.yaml", where, "invalid parent/child body index");
    ChainJoint j;
    j.type = s.type;
    j.parent = s.parent_index;
    j.child = s.child_index;
    j.dof = s.type == JointType::kHinge ? 1 : 3;
    j.c_parent = s.center_parent;
    j.c_child = s.center_child;
    if (!j.c_parent.allFinite() || !j.c_child.allFinite())
      return make_error("model.yaml", where, "joint centres must be finite");
    if (s.type == JointType::kHinge) {
      if (!s.axis_parent.allFinite() || !s.axis_child.allFinite() ||
          s.axis_parent.norm() < 1e-9 || s.axis_child.norm() < 1e-9)
        return make_error("model.yaml", where, "hinge needs finite, non-zero axes");
      j.axis_parent = s.axis_parent.normalized();
      j.axis_child = s.axis_child.normalized();
      const Mat3 R_parent_C =
          kinematics::make_hinge_frame(s.center_parent, s.axis_parent).T_body_joint.linear();
      const Mat3 R_child_C =
          kinematics::make_hinge_frame(s.center_child, s.axis_child).T_body_joint.linear();
      j.R_zero = R_parent_C * R_child_C.transpose();  // frame C of the child onto the parent's
    }
    m.joints_.push_back(j);
  }
  // A forest: each body the child of at most one chain joint, no loops.
  for (int ji = 0; ji < static_cast<int>(m.joints_.size()); ++ji) {
    ChainJoint& j = m.joints_[static_cast<std::size_t>(ji)];
    int& into = m.joint_into_[static_cast<std::size_t>(j.child)];
    if (into >= 0) {
      m.warnings_.push_back("model.yaml: joints." + model.joints[static_cast<std::size_t>(ji)].name +
                            ": body '" + model.joints[static_cast<std::size_t>(ji)].child +
                            "' already has a parent joint; its angle comes from the two poses only");
      continue;
    }
    // Walking up from the parent must not reach the child (a loop).
    bool loop = false;
    for (int b = j.parent, steps = 0; b >= 0 && steps <= nb; ++steps) {
      if (b == j.child) {
        loop = true;
        break;
      }
      const int up = m.joint_into_[static_cast<std::size_t>(b)];
      b = up < 0 ? -1 : m.joints_[static_cast<std::size_t>(up)].parent;
    }
    if (loop) {
      m.warnings_.push_back("model.yaml: joints." + model.joints[static_cast<std::size_t>(ji)].name +
                            ": closes a loop; its angle comes from the two poses only");
      continue;
    }
    into = ji;
    j.in_chain = true;
  }
  // Topological order: a joint after the joint into its parent body.
  std::vector<int> depth(m.joints_.size(), 0);
  for (std::size_t ji = 0; ji < m.joints_.size(); ++ji) {
    if (!m.joints_[ji].in_chain) continue;
    int d = 0;
    for (int b = m.joints_[ji].parent; m.joint_into_[static_cast<std::size_t>(b)] >= 0 && d <= nb;
         ++d)
      b = m.joints_[static_cast<std::size_t>(m.joint_into_[static_cast<std::size_t>(b)])].parent;
    depth[ji] = d;
  }
  for (int d = 0; d <= nb; ++d)
    for (std::size_t ji = 0; ji < m.joints_.size(); ++ji)
      if (m.joints_[ji].in_chain && depth[ji] == d) m.order_.push_back(static_cast<int>(ji));
  return m;
}

Mat3 ChainModel::hinge_rotation(int j, double theta) const noexcept {
  const ChainJoint& cj = joint(j);
  return Eigen::AngleAxisd(theta, cj.axis_parent).toRotationMatrix() * cj.R_zero;
}

Iso3 ChainModel::parent_child(int j, const Mat3& R_parent_child) const noexcept {
  const ChainJoint& cj = joint(j);
  return make_iso(R_parent_child, cj.c_parent - R_parent_child * cj.c_child);
}

}  // namespace mocap
