// Design: see frame_result_builder.h. The message mirrors FrameOutput::angles in model
// order; joints beyond client::kMaxJoints are not sent (the model loader bounds the count).
#include "pipeline/frame_result_builder.h"

#include <algorithm>
#include <cmath>

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
    client::JointQuality& q = msg.quality[j];
    q = client::JointQuality{};
    q.solved_by =
        static_cast<std::uint8_t>(a.valid ? client::SolvedBy::kPoses : client::SolvedBy::kNone);
  }
  for (std::size_t j = n; j < client::kMaxJoints; ++j) {
    msg.joints[j] = client::JointRecord{};
    msg.quality[j] = client::JointQuality{};
  }
}

void make_frame_result(std::uint64_t sequence, std::int64_t capture_ns, const TargetSet& targets,
                       const FrameOutput& out, publish::FrameResult& result) noexcept {
  make_joints_message(sequence, capture_ns, out, result.joints);
  const int bodies = std::min(
      {out.poses.count, publish::kMaxResultBodies, static_cast<int>(targets.bodies.size())});
  const int points = std::min(out.points.size(), publish::kMaxResultPoints);
  result.body_count = bodies;
  result.point_count = points;
  for (int i = 0; i < points; ++i) {
    const Point3& p = out.points[i];
    publish::ResultPoint& r = result.points[static_cast<std::size_t>(i)];
    r.X_world_mm = {static_cast<float>(p.X_world.x()), static_cast<float>(p.X_world.y()),
                    static_cast<float>(p.X_world.z())};
    r.reproj_px = static_cast<float>(p.reproj_px);
    int cameras = 0;
    for (std::int16_t b : p.blob_index) cameras += b >= 0 ? 1 : 0;
    r.cameras = static_cast<std::uint8_t>(cameras);
  }
  int markers = 0;
  for (int b = 0; b < bodies; ++b) {
    const BodyPose& pose = out.poses.bodies[static_cast<std::size_t>(b)];
    publish::ResultBody& rb = result.bodies[static_cast<std::size_t>(b)];
    rb = publish::ResultBody{};
    if (!pose.found) continue;
    rb.found = 1;
    rb.markers = static_cast<std::uint8_t>(std::clamp(pose.markers, 0, 255));
    rb.rms_mm = static_cast<float>(pose.rms_mm);
    Quat q(pose.T_world_body.linear());
    q.normalize();
    if (q.w() < 0.0) q.coeffs() = -q.coeffs();
    rb.q_world_body = {q.w(), q.x(), q.y(), q.z()};
    const Vec3 t = pose.T_world_body.translation();
    rb.t_world_body_mm = {t.x(), t.y(), t.z()};
    const std::vector<Vec3>& model = targets.bodies[static_cast<std::size_t>(b)].markers_body;
    const std::size_t nk = std::min<std::size_t>(model.size(), pose.point_index_of_marker.size());
    for (std::size_t k = 0; k < nk && markers < publish::kMaxResultMarkers; ++k) {
      const int idx = pose.point_index_of_marker[k];
      if (idx < 0 || idx >= out.points.size()) continue;
      const Vec3& X = out.points[idx].X_world;
      publish::ResultMarker& m = result.markers[static_cast<std::size_t>(markers++)];
      m.body = static_cast<std::uint8_t>(b);
      m.marker = static_cast<std::uint8_t>(k);
      m.residual_mm = static_cast<float>((X - pose.T_world_body * model[k]).norm());
      m.X_world_mm = {static_cast<float>(X.x()), static_cast<float>(X.y()),
                      static_cast<float>(X.z())};
    }
  }
  result.marker_count = markers;
}

}  // namespace mocap::pipeline
