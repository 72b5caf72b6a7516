// Design: see frame_result_builder.h. The message mirrors FrameOutput::angles in model
// order; joints beyond client::kMaxJoints are not sent (the model loader bounds the count).
#include "pipeline/frame_result_builder.h"

#include <algorithm>
#include <bitset>
#include <cmath>
#include <numbers>

#include "core/rotation.h"

namespace mocap::pipeline {

// Every output carries the whole robot (interfaces.md, "The whole robot"): nothing the
// tracker produces is cut by the output record.
static_assert(publish::kMaxResultBodies >= kMaxBodies, "FrameResult holds every body");
static_assert(publish::kMaxResultMarkers >= kMaxLabelledMarkers, "and every labelled marker");
static_assert(publish::kMaxResultPoints >= kMaxPoints, "and every point identification takes");
static_assert(client::kMaxJoints >= kMaxBodies, "and every joint (chain_solver.cpp's bound)");

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
  msg.lead_us = 0;
  for (std::size_t j = 0; j < n; ++j) {
    const kinematics::JointAngle& a = out.angles.joints[j];
    client::JointRecord& r = msg.joints[j];
    r.index = static_cast<std::uint16_t>(j);
    r.type = static_cast<std::uint8_t>(a.type);  // client::JointKind is JointType
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
    q.solved_by = static_cast<std::uint8_t>(a.valid ? a.solved_by : client::SolvedBy::kNone);
    for (std::size_t k = 0; k < 3; ++k) q.sd_rad[k] = static_cast<float>(a.sd_rad[k]);
    client::JointRates& rt = msg.rates[j];
    rt = client::JointRates{};
    rt.valid = a.valid && a.rate_valid ? 1 : 0;
    for (std::size_t k = 0; rt.valid && k < 3; ++k) {
      rt.rate_rad_s[k] = static_cast<float>(a.rate_rad_s[k]);
      rt.sd_rad_s[k] = static_cast<float>(a.rate_sd_rad_s[k]);
    }
  }
  for (std::size_t j = n; j < client::kMaxJoints; ++j) {
    msg.joints[j] = client::JointRecord{};
    msg.quality[j] = client::JointQuality{};
    msg.rates[j] = client::JointRates{};
  }
}

void make_frame_result(std::uint64_t sequence, std::int64_t capture_ns, const TargetSet& targets,
                       const FrameOutput& out, LabelledMarkers& labelled,
                       publish::FrameResult& result) noexcept {
  make_joints_message(sequence, capture_ns, out, result.joints);
  const int bodies = std::min(
      {out.poses.count, publish::kMaxResultBodies, static_cast<int>(targets.bodies.size())});
  result.body_count = bodies;
  // The frame's 3D points as points.csv has them: the reported candidates (a candidate
  // that lost its blob to a better one, track/point_selection.h, is not a point).
  int points = 0;
  for (int i = 0; i < out.points.size() && points < publish::kMaxResultPoints; ++i) {
    const Point3& p = out.points[i];
    if (!p.reported) continue;
    publish::ResultPoint& r = result.points[static_cast<std::size_t>(points++)];
    r.X_world_mm = {static_cast<float>(p.X_world.x()), static_cast<float>(p.X_world.y()),
                    static_cast<float>(p.X_world.z())};
    r.reproj_px = static_cast<float>(p.reproj_px);
    r.cameras = static_cast<std::uint8_t>(p.blob_index.count());
  }
  result.point_count = points;
  int markers = 0;
  for (int b = 0; b < bodies; ++b) {
    const BodyPose& pose = out.poses.bodies[static_cast<std::size_t>(b)];
    publish::ResultBody& rb = result.bodies[static_cast<std::size_t>(b)];
    rb = publish::ResultBody{};
    if (!pose.found) continue;
    rb.found = 1;
    rb.markers = static_cast<std::uint8_t>(std::clamp(pose.markers, 0, 255));
    rb.rms_mm = static_cast<float>(pose.rms_mm);
    const Quat q = canonical_quat(pose.T_world_body.linear());
    rb.q_world_body = {q.w(), q.x(), q.y(), q.z()};
    const Vec3 t = pose.T_world_body.translation();
    rb.t_world_body_mm = {t.x(), t.y(), t.z()};
    if (static_cast<std::size_t>(b) < out.body_rates.size()) {
      const kinematics::BodyRate& r = out.body_rates[static_cast<std::size_t>(b)];
      rb.velocity_valid = r.valid ? 1 : 0;
      for (int k = 0; r.valid && k < 3; ++k) {
        const auto uk = static_cast<std::size_t>(k);
        rb.v_world_mm_s[uk] = static_cast<float>(r.v_world_mm_s[k]);
        rb.w_world_rad_s[uk] = static_cast<float>(r.w_world_rad_s[k]);
      }
    }
  }
  // The labelled markers: the one list of the frame (track/labelled_markers.h).
  label_markers(out, targets, labelled);
  for (int i = 0; i < labelled.count && markers < publish::kMaxResultMarkers; ++i) {
    const LabelledMarker& l = labelled.items[static_cast<std::size_t>(i)];
    if (l.body >= bodies) continue;
    publish::ResultMarker& m = result.markers[static_cast<std::size_t>(markers++)];
    m.body = static_cast<std::uint8_t>(l.body);
    m.marker = static_cast<std::uint8_t>(l.marker);
    m.residual_mm = static_cast<float>(l.residual_mm);
    m.X_world_mm = {static_cast<float>(l.X_world_mm.x()), static_cast<float>(l.X_world_mm.y()),
                    static_cast<float>(l.X_world_mm.z())};
  }
  result.marker_count = markers;
  // Which of result.points a body claimed (ResultPoint::labelled; ROS 2's unlabelled
  // cloud is the rest). result.points skips the points that are not reported, so the
  // claimed out.points indices are mapped by walking both lists in step.
  std::bitset<publish::kMaxResultPoints> claimed;
  for (int i = 0; i < labelled.count; ++i) {
    const int p = labelled.items[static_cast<std::size_t>(i)].point;
    if (p >= 0 && p < publish::kMaxResultPoints) claimed[static_cast<std::size_t>(p)] = true;
  }
  for (int p = 0, r = 0; p < out.points.size() && r < points; ++p) {
    if (!out.points[p].reported) continue;
    result.points[static_cast<std::size_t>(r++)].labelled =
        p < publish::kMaxResultPoints && claimed[static_cast<std::size_t>(p)] ? 1 : 0;
  }

  // Each camera's blobs, and what they became: a labelled marker, a point, or nothing.
  const int cameras = std::min(static_cast<int>(out.blobs.size()), publish::kMaxResultCameras);
  const int per_camera = publish::result_blobs_per_camera(cameras);
  result.camera_count = cameras;
  for (int c = 0; c < cameras; ++c) {
    const detect::BlobList& blobs = out.blobs[static_cast<std::size_t>(c)];
    publish::CameraBlobs& cb = result.cameras[static_cast<std::size_t>(c)];
    cb.present = out.camera_present[static_cast<std::size_t>(c)] ? 1 : 0;
    cb.count = std::min(static_cast<int>(blobs.size()), per_camera);
    cb.first = c * per_camera;
    publish::ResultBlob* const kept = result.blobs_of(c);
    for (int i = 0; i < cb.count; ++i) {
      const detect::Blob& b = blobs[static_cast<std::size_t>(i)];
      publish::ResultBlob& r = kept[i];
      r = publish::ResultBlob{};
      r.x_px = static_cast<float>(b.x_px);
      r.y_px = static_cast<float>(b.y_px);
      r.diameter_px = 2.0f * std::sqrt(std::max(0.0f, b.area_px) / std::numbers::pi_v<float>);
    }
  }
  const auto blob_of = [&](int point, int c) -> publish::ResultBlob* {
    if (point < 0 || point >= out.points.size()) return nullptr;
    const std::int16_t bi = out.points[point].blob_index[static_cast<std::size_t>(c)];
    const publish::CameraBlobs& cb = result.cameras[static_cast<std::size_t>(c)];
    if (bi < 0 || bi >= cb.count) return nullptr;
    return result.blobs_of(c) + bi;
  };
  for (int p = 0; p < out.points.size(); ++p) {
    if (!out.points[p].reported) continue;
    out.points[p].blob_index.for_each([&](int c, int) {
      if (c >= cameras) return;
      if (publish::ResultBlob* r = blob_of(p, c))
        r->use = static_cast<std::uint8_t>(publish::BlobUse::kPoint);
    });
  }
  for (int i = 0; i < labelled.count; ++i) {
    const LabelledMarker& l = labelled.items[static_cast<std::size_t>(i)];
    if (l.point < 0 || l.point >= out.points.size()) continue;
    out.points[l.point].blob_index.for_each([&](int c, int) {
      publish::ResultBlob* r = c < cameras ? blob_of(l.point, c) : nullptr;
      if (r == nullptr) return;
      r->use = static_cast<std::uint8_t>(publish::BlobUse::kMarker);
      r->body = static_cast<std::uint8_t>(std::clamp<int>(l.body, 0, 255));
      r->marker = static_cast<std::uint8_t>(std::clamp<int>(l.marker, 0, 255));
    });
  }
}

}  // namespace mocap::pipeline
