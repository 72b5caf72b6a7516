// Design: see joints_sink.h. The message mirrors FrameOutput::angles in model order;
// joints beyond client::kMaxJoints are not sent (the model loader bounds the count).
#include "pipeline/joints_sink.h"

#include <algorithm>

namespace mocap::pipeline {

void make_joints_message(std::uint64_t sequence, std::int64_t capture_ns, const FrameOutput& out,
                         client::JointsMessage& msg) noexcept {
  msg.sequence = sequence;
  msg.capture_ns = capture_ns;
  msg.publish_ns = 0;
  msg.flags = (out.poses.count > 0 && out.poses.found == out.poses.count)
                  ? client::kFlagAllBodiesFound
                  : 0u;
  const std::size_t n = std::min<std::size_t>(out.angles.joints.size(), client::kMaxJoints);
  msg.joint_count = static_cast<std::uint16_t>(n);
  msg.reserved = 0;
  for (std::size_t j = 0; j < n; ++j) {
    const kinematics::JointAngle& a = out.angles.joints[j];
    client::JointRecord& r = msg.joints[j];
    r.index = static_cast<std::uint16_t>(j);
    r.type = static_cast<std::uint8_t>(a.type == JointType::kHinge ? client::JointKind::kHinge
                                                                   : client::JointKind::kBall);
    r.valid = a.valid ? 1 : 0;
    r.a[0] = static_cast<float>(a.a0);
    r.a[1] = static_cast<float>(a.a1);
    r.a[2] = static_cast<float>(a.a2);
    r.q[0] = static_cast<float>(a.q_parent_child.w());
    r.q[1] = static_cast<float>(a.q_parent_child.x());
    r.q[2] = static_cast<float>(a.q_parent_child.y());
    r.q[3] = static_cast<float>(a.q_parent_child.z());
    client::JointQuality& qual = msg.quality[j];
    qual = client::JointQuality{};
    qual.solved_by = static_cast<std::uint8_t>(a.valid ? a.solved_by : client::SolvedBy::kNone);
    for (std::size_t k = 0; k < 3; ++k) qual.sd_rad[k] = static_cast<float>(a.sd_rad[k]);
  }
  for (std::size_t j = n; j < client::kMaxJoints; ++j) {
    msg.joints[j] = client::JointRecord{};
    msg.quality[j] = client::JointQuality{};
  }
}

}  // namespace mocap::pipeline
