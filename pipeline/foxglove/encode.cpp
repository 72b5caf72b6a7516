// Design: see encode.h. Counts from the FrameResult are clamped to its capacities and
// to the scene's sizes, so a damaged result never reads out of bounds.
#include "pipeline/foxglove/encode.h"

#include <algorithm>
#include <cmath>
#include <nlohmann/json.hpp>

#include "pipeline/foxglove/schemas.h"

namespace mocap::foxglove {

using nlohmann::json;

namespace {

constexpr double kMetresPerMm = 1e-3;

json stamp(std::int64_t ns) {
  if (ns < 0) ns = 0;
  return {{"sec", ns / 1000000000}, {"nsec", ns % 1000000000}};
}
// JSON has no NaN/inf (nlohmann would write null, which breaks the schema): a non-finite
// value is written as 0.
double finite(double v) { return std::isfinite(v) ? v : 0.0; }
json vec(double x, double y, double z) {
  return {{"x", finite(x)}, {"y", finite(y)}, {"z", finite(z)}};
}
// Invalid UTF-8 in a name (for example a body name) is replaced, never thrown.
std::string dump(const json& j) { return j.dump(-1, ' ', false, json::error_handler_t::replace); }
json vec_m(const Vec3& mm) {
  return vec(mm.x() * kMetresPerMm, mm.y() * kMetresPerMm, mm.z() * kMetresPerMm);
}
json quat(const Quat& q) {
  return {{"x", finite(q.x())}, {"y", finite(q.y())}, {"z", finite(q.z())}, {"w", finite(q.w())}};
}
json colour(const Rgba& c) { return {{"r", c.r}, {"g", c.g}, {"b", c.b}, {"a", c.a}}; }
json pose(const Vec3& position_mm, const Quat& q) {
  return {{"position", vec_m(position_mm)}, {"orientation", quat(q)}};
}
json sphere(const Vec3& centre_mm, double diameter_mm, const Rgba& c) {
  const double d = diameter_mm * kMetresPerMm;
  return {
      {"pose", pose(centre_mm, Quat::Identity())}, {"size", vec(d, d, d)}, {"color", colour(c)}};
}

int clamp_count(std::int32_t n, int capacity) {
  return std::clamp(static_cast<int>(n), 0, capacity);
}

Quat body_rotation(const publish::ResultBody& b) {
  Quat q(b.q_world_body[0], b.q_world_body[1], b.q_world_body[2], b.q_world_body[3]);
  const double n = q.norm();
  return (std::isfinite(n) && n > 0.0) ? Quat(q.coeffs() / n) : Quat::Identity();
}
Vec3 body_translation_mm(const publish::ResultBody& b) {
  return Vec3(b.t_world_body_mm[0], b.t_world_body_mm[1], b.t_world_body_mm[2]);
}
Vec3 to_vec3(const std::array<float, 3>& p) {
  return Vec3(static_cast<double>(p[0]), static_cast<double>(p[1]), static_cast<double>(p[2]));
}

json entity(const FoxgloveScene& scene, const json& ts, const char* id) {
  return {{"timestamp", ts},
          {"frame_id", scene.world_frame},
          {"id", id},
          {"lifetime", {{"sec", 0}, {"nsec", 0}}},
          {"frame_locked", false},
          {"metadata", json::array()},
          {"arrows", json::array()},
          {"cubes", json::array()},
          {"spheres", json::array()},
          {"cylinders", json::array()},
          {"lines", json::array()},
          {"triangles", json::array()},
          {"texts", json::array()},
          {"models", json::array()}};
}

}  // namespace

std::vector<ChannelInfo> live_view_channels(const FoxgloveScene& scene) {
  std::vector<ChannelInfo> channels = {
      ChannelInfo{kChannelTf, "/tf", "foxglove.FrameTransforms", frame_transforms_schema()},
      ChannelInfo{kChannelMarkers, "/markers", "foxglove.SceneUpdate", scene_update_schema()},
      ChannelInfo{kChannelJoints, "/joints", "mocap.JointAngles", joints_schema()},
      ChannelInfo{kChannelBodies, "/bodies", "mocap.BodyStates", bodies_schema()}};
  for (std::size_t c = 0; c < scene.cameras.size(); ++c) {
    channels.push_back(ChannelInfo{kChannelBlobsFirst + static_cast<std::uint32_t>(c),
                                   "/" + scene.cameras[c].name + "/blobs", "foxglove.RawImage",
                                   raw_image_schema()});
  }
  return channels;
}

std::string encode_frame_transforms(const FoxgloveScene& scene, const publish::FrameResult& frame,
                                    std::int64_t stamp_ns) {
  const json ts = stamp(stamp_ns);
  json transforms = json::array();
  const int n = std::min(clamp_count(frame.body_count, publish::kMaxResultBodies),
                         static_cast<int>(scene.bodies.size()));
  for (int i = 0; i < n; ++i) {
    const publish::ResultBody& b = frame.bodies[i];
    if (b.found == 0) continue;
    transforms.push_back({{"timestamp", ts},
                          {"parent_frame_id", scene.world_frame},
                          {"child_frame_id", scene.bodies[i].name},
                          {"translation", vec_m(body_translation_mm(b))},
                          {"rotation", quat(body_rotation(b))}});
  }
  return dump(json({{"transforms", std::move(transforms)}}));
}

std::string encode_scene_update(const FoxgloveScene& scene, const publish::FrameResult& frame,
                                std::int64_t stamp_ns) {
  const json ts = stamp(stamp_ns);
  const double d = scene.marker_diameter_mm;
  json points = entity(scene, ts, "points");
  const Rgba grey{0.6, 0.6, 0.6, 0.8};
  for (int i = 0; i < clamp_count(frame.point_count, publish::kMaxResultPoints); ++i) {
    points["spheres"].push_back(sphere(to_vec3(frame.points[i].X_world_mm), 0.5 * d, grey));
  }
  json markers = entity(scene, ts, "markers");
  const int bodies = static_cast<int>(scene.bodies.size());
  for (int i = 0; i < clamp_count(frame.marker_count, publish::kMaxResultMarkers); ++i) {
    const publish::ResultMarker& m = frame.markers[i];
    const Rgba c = m.body < bodies ? scene.bodies[m.body].colour : Rgba{};
    markers["spheres"].push_back(sphere(to_vec3(m.X_world_mm), d, c));
  }
  json labels = entity(scene, ts, "bodies");
  json joints = entity(scene, ts, "joints");
  const int found_n = std::min(clamp_count(frame.body_count, publish::kMaxResultBodies), bodies);
  for (int i = 0; i < found_n; ++i) {
    if (frame.bodies[i].found == 0) continue;
    Rgba c = scene.bodies[i].colour;
    labels["texts"].push_back(
        {{"pose", pose(body_translation_mm(frame.bodies[i]), Quat::Identity())},
         {"billboard", true},
         {"font_size", 14.0},
         {"scale_invariant", true},
         {"color", colour(c)},
         {"text", scene.bodies[i].name}});
  }
  const Rgba centre_colour{1.0, 1.0, 1.0, 0.9};
  const Rgba axis_colour{1.0, 0.85, 0.1, 1.0};
  constexpr double kAxisLengthMm = 80.0;
  for (const SceneJoint& j : scene.joints) {
    if (!j.calibrated || j.parent < 0 || j.parent >= found_n || frame.bodies[j.parent].found == 0) {
      continue;
    }
    const Quat R = body_rotation(frame.bodies[j.parent]);
    const Vec3 centre = R * j.center_parent_mm + body_translation_mm(frame.bodies[j.parent]);
    joints["spheres"].push_back(sphere(centre, 1.5 * d, centre_colour));
    if (j.type != JointType::kHinge) continue;
    const Vec3 axis = R * j.axis_parent;
    const Quat along = Quat::FromTwoVectors(Vec3::UnitX(), axis);
    joints["arrows"].push_back({{"pose", pose(centre - 0.5 * kAxisLengthMm * axis, along)},
                                {"shaft_length", 0.8 * kAxisLengthMm * kMetresPerMm},
                                {"shaft_diameter", 3.0 * kMetresPerMm},
                                {"head_length", 0.2 * kAxisLengthMm * kMetresPerMm},
                                {"head_diameter", 8.0 * kMetresPerMm},
                                {"color", colour(axis_colour)}});
  }
  json update = {
      {"deletions", json::array()},
      {"entities", {std::move(points), std::move(markers), std::move(labels), std::move(joints)}}};
  return dump(update);
}

std::string encode_body_states(const FoxgloveScene& scene, const publish::FrameResult& frame,
                               std::int64_t stamp_ns) {
  json list = json::array();
  const int n = std::min(clamp_count(frame.body_count, publish::kMaxResultBodies),
                         static_cast<int>(scene.bodies.size()));
  for (int i = 0; i < n; ++i) {
    const publish::ResultBody& b = frame.bodies[i];
    json body = {{"name", scene.bodies[i].name}, {"found", b.found != 0}};
    if (b.found != 0) {
      const bool v = b.velocity_valid != 0;
      body["markers"] = b.markers;
      body["rms_mm"] = finite(static_cast<double>(b.rms_mm));
      body["position"] = vec_m(body_translation_mm(b));
      body["orientation"] = quat(body_rotation(b));
      body["velocity_m_s"] =
          v ? json::array({finite(static_cast<double>(b.v_world_mm_s[0]) * kMetresPerMm),
                           finite(static_cast<double>(b.v_world_mm_s[1]) * kMetresPerMm),
                           finite(static_cast<double>(b.v_world_mm_s[2]) * kMetresPerMm)})
            : json(nullptr);
      body["angular_velocity_rad_s"] =
          v ? json::array({finite(static_cast<double>(b.w_world_rad_s[0])),
                           finite(static_cast<double>(b.w_world_rad_s[1])),
                           finite(static_cast<double>(b.w_world_rad_s[2]))})
            : json(nullptr);
    }
    list.push_back(std::move(body));
  }
  return dump(json({{"timestamp", stamp(stamp_ns)},
                    {"sequence", frame.joints.sequence},
                    {"frame_id", scene.world_frame},
                    {"bodies", std::move(list)}}));
}

std::string encode_joint_angles(const FoxgloveScene& scene, const publish::FrameResult& frame,
                                std::int64_t stamp_ns) {
  static constexpr const char* kSolvedBy[] = {"none", "poses", "chain"};
  const client::JointsMessage& msg = frame.joints;
  json list = json::array();
  const int n = std::min<int>(msg.joint_count, client::kMaxJoints);
  for (int i = 0; i < n; ++i) {
    const client::JointRecord& r = msg.joints[i];
    const client::JointQuality& q = msg.quality[i];
    const bool hinge = r.type == static_cast<std::uint8_t>(client::JointKind::kHinge);
    const int dof = hinge ? 1 : 3;
    const client::JointRates& rt = msg.rates[i];
    json angles = json::array();
    json sd = json::array();
    json rates = rt.valid ? json::array() : json(nullptr);
    json rates_sd = rt.valid ? json::array() : json(nullptr);
    for (int k = 0; k < dof; ++k) {
      angles.push_back(finite(static_cast<double>(r.a[k])));
      sd.push_back(finite(static_cast<double>(q.sd_rad[k])));
      if (!rt.valid) continue;
      rates.push_back(finite(static_cast<double>(rt.rate_rad_s[k])));
      rates_sd.push_back(finite(static_cast<double>(rt.sd_rad_s[k])));
    }
    const std::string name = r.index < scene.joints.size() ? scene.joints[r.index].name
                                                           : "joint" + std::to_string(r.index);
    list.push_back({{"name", name},
                    {"type", hinge ? "hinge" : "ball"},
                    {"valid", r.valid != 0},
                    {"angles_rad", std::move(angles)},
                    {"solved_by", q.solved_by < 3 ? kSolvedBy[q.solved_by] : "none"},
                    {"sd_rad", std::move(sd)},
                    {"rate_rad_s", std::move(rates)},
                    {"rate_sd_rad_s", std::move(rates_sd)}});
  }
  return dump(json({{"timestamp", stamp(stamp_ns)},
                    {"sequence", msg.sequence},
                    {"all_bodies_found", (msg.flags & client::kFlagAllBodiesFound) != 0},
                    {"joints", std::move(list)}}));
}

}  // namespace mocap::foxglove
