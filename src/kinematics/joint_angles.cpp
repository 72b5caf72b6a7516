// Design: see joint_angles.h.
#include "kinematics/joint_angles.h"

#include <cmath>
#include <numbers>

#include "core/rotation.h"
#include "kinematics/joint_frame.h"

namespace mocap::kinematics {

double hinge_angle(const Mat3& R_parent_C, const Vec3& x_child_C,
                   const Mat3& R_parent_child) noexcept {
  const Vec3 d = R_parent_child * x_child_C;  // child's reference, parent coordinates
  return std::atan2(d.dot(R_parent_C.col(1)), d.dot(R_parent_C.col(0)));
}

Expected<JointAngleSolver> JointAngleSolver::create(const JointModel& model,
                                                    std::size_t num_bodies) {
  JointAngleSolver s;
  s.num_bodies_ = num_bodies;
  const int nb = static_cast<int>(num_bodies);
  for (const auto& j : model.joints) {
    const std::string where = "joints." + j.name;
    if (!j.calibrated) return make_error("model.yaml", where, "joint is not calibrated");
    if (j.parent_index < 0 || j.parent_index >= nb || j.child_index < 0 || j.child_index >= nb ||
        j.parent_index == j.child_index) {
      return make_error("model.yaml", where, "invalid parent/child body index");
    }
    Joint out;
    out.type = j.type;
    out.parent = j.parent_index;
    out.child = j.child_index;
    if (j.type == JointType::kHinge) {
      if (!j.axis_parent.allFinite() || !j.axis_child.allFinite() || !j.center_parent.allFinite() ||
          !j.center_child.allFinite() || j.axis_parent.norm() < 1e-9 ||
          j.axis_child.norm() < 1e-9) {
        return make_error("model.yaml", where, "hinge needs finite centres and non-zero axes");
      }
      out.R_parent_C = make_hinge_frame(j.center_parent, j.axis_parent).T_body_joint.linear();
      out.x_child_C = make_hinge_frame(j.center_child, j.axis_child).T_body_joint.linear().col(0);
    }
    s.joints_.push_back(out);
  }
  return s;
}

JointAngles JointAngleSolver::make_output() const {
  JointAngles out;
  out.joints.resize(joints_.size());
  for (std::size_t i = 0; i < joints_.size(); ++i) out.joints[i].type = joints_[i].type;
  return out;
}

bool JointAngleSolver::compute(const BodyPoseView* poses, JointAngles& out) noexcept {
  if (out.joints.size() != joints_.size()) return false;
  constexpr double kTwoPi = 2.0 * std::numbers::pi;
  int valid = 0;
  for (std::size_t i = 0; i < joints_.size(); ++i) {
    Joint& j = joints_[i];
    JointAngle& a = out.joints[i];
    a.type = j.type;
    const BodyPoseView& p = poses[j.parent];
    const BodyPoseView& c = poses[j.child];
    a.valid = p.found && c.found;
    a.solved_by = a.valid ? client::SolvedBy::kPoses : client::SolvedBy::kNone;
    a.sd_rad = {0.0, 0.0, 0.0};
    if (!a.valid) continue;
    const Mat3 R = p.T_world_body.linear().transpose() * c.T_world_body.linear();
    a.q_parent_child = canonical_quat(R);
    if (j.type == JointType::kBall) {
      const Vec3 e = rotation_to_euler_xyz(R);
      a.a0 = e[0];
      a.a1 = e[1];
      a.a2 = e[2];
    } else {
      double angle = hinge_angle(j.R_parent_C, j.x_child_C, R);
      if (j.has_previous) {
        // Add the multiple of 2 pi that brings the angle closest to the previous one.
        angle += kTwoPi * std::round((j.previous_rad - angle) / kTwoPi);
      }
      j.previous_rad = angle;
      j.has_previous = true;
      a.a0 = angle;
      a.a1 = 0.0;
      a.a2 = 0.0;
    }
    ++valid;
  }
  out.valid_count = valid;
  return true;
}

void JointAngleSolver::reset() noexcept {
  for (auto& j : joints_) j.has_previous = false;
}

}  // namespace mocap::kinematics
