// Design: see ros2_mapping.h.
#include "pipeline/publish/ros2/ros2_mapping.h"

#include <time.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>

#include "core/rotation.h"
#include "formats/text_io.h"

namespace mocap::publish::ros2 {

std::vector<JointDof> joint_dofs(const JointModel& model, int max_joints) {
  std::vector<JointDof> dofs;
  const int n = std::min(static_cast<int>(model.joints.size()), max_joints);
  for (int j = 0; j < n; ++j) {
    const JointSpec& s = model.joints[static_cast<std::size_t>(j)];
    if (s.type == JointType::kHinge) {
      dofs.push_back({s.name, j, 0});
    } else {
      dofs.push_back({s.name + "_x", j, 0});
      dofs.push_back({s.name + "_y", j, 1});
      dofs.push_back({s.name + "_z", j, 2});
    }
  }
  return dofs;
}

Expected<std::uint32_t> parse_domain_id(const char* value) {
  if (value == nullptr || value[0] == '\0') return std::uint32_t{0};
  const std::string v(value);
  std::uint32_t id = 0;
  bool ok = v.size() <= 3;
  for (char c : v) {
    if (!ok) break;
    ok = c >= '0' && c <= '9';
    id = id * 10 + static_cast<std::uint32_t>(c - '0');
  }
  if (!ok || id > 232)
    return make_error("ROS_DOMAIN_ID", "'" + v + "'", "expected an integer in 0..232");
  return id;
}

Stamp to_stamp(std::int64_t monotonic_ns, std::int64_t offset_ns) noexcept {
  std::int64_t t = monotonic_ns + offset_ns;
  if (t < 0) t = 0;
  Stamp s;
  s.sec = static_cast<std::int32_t>(
      std::min<std::int64_t>(t / 1'000'000'000, std::numeric_limits<std::int32_t>::max()));
  s.nanosec = static_cast<std::uint32_t>(t % 1'000'000'000);
  return s;
}

namespace {

WorldRotation rotation_of(const Mat3& R_frame_world) {
  WorldRotation r;
  r.identity = false;
  const Quat q = canonical_quat(R_frame_world);
  r.q_frame_world = {q.w(), q.x(), q.y(), q.z()};
  const Mat3 R = q.toRotationMatrix();
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) r.R_frame_world[static_cast<std::size_t>(3 * i + j)] = R(i, j);
  return r;
}

}  // namespace

Expected<WorldRotation> parse_world_rotation(const std::string& text, const std::string& where) {
  if (text == "identity") return WorldRotation{};
  if (text == "camera_to_z_up") {  // x_frame = z_cam, y_frame = -x_cam, z_frame = -y_cam
    Mat3 R;
    R << 0, 0, 1, -1, 0, 0, 0, -1, 0;
    return rotation_of(R);
  }
  if (text == "y_up_to_z_up") {  // (x, y, z) -> (x, -z, y): +90 degrees about x
    Mat3 R;
    R << 1, 0, 0, 0, 0, -1, 0, 1, 0;
    return rotation_of(R);
  }
  const auto bad = [&](const std::string& what) {
    return make_error(where, "world_rotation", what + ", got '" + text + "'");
  };
  const std::string expected =
      "expected identity, camera_to_z_up, y_up_to_z_up or a unit quaternion 'qw qx qy qz'";
  double q[4] = {0, 0, 0, 0};
  int n = 0;
  std::size_t at = 0;
  for (;;) {
    at = text.find_first_not_of(" ,\t", at);
    if (at == std::string::npos) break;
    const std::size_t end = std::min(text.find_first_of(" ,\t", at), text.size());
    if (n == 4 || formats_detail::parse_double(std::string_view(text).substr(at, end - at), q[n]) !=
                      formats_detail::NumberStatus::kOk)
      return bad(expected);
    ++n;
    at = end;
  }
  if (n != 4) return bad(expected);
  const double norm = std::sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
  if (std::abs(norm - 1.0) > 1e-3) return bad("the quaternion's norm is not 1 (within 1e-3)");
  return rotation_of(Quat(q[0] / norm, q[1] / norm, q[2] / norm, q[3] / norm).toRotationMatrix());
}

Expected<void> check_frame_id(const std::string& frame_id, const std::string& where) {
  bool ok = !frame_id.empty() && frame_id.size() <= 256 && frame_id[0] != '/';
  for (const char c : frame_id)
    ok = ok && ((c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') ||
                c == '_' || c == '-' || c == '.' || c == '/');
  if (!ok)
    return make_error(where, "frame_id",
                      "expected 1..256 letters, digits, '_', '-', '.', '/' not starting with "
                      "'/', got '" +
                          frame_id + "'");
  return {};
}

std::string topic_token(const std::string& body) {
  std::string t;
  if (!body.empty() && body[0] >= '0' && body[0] <= '9') t += '_';
  for (const char c : body) {
    const bool ok = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9');
    t += ok ? c : '_';
  }
  return t;
}

Expected<std::vector<std::string>> pose_topics(const std::vector<std::string>& bodies) {
  std::vector<std::string> topics;
  for (std::size_t b = 0; b < bodies.size(); ++b) {
    topics.push_back("rt/mocap/" + topic_token(bodies[b]) + "/pose");
    for (std::size_t a = 0; a < b; ++a)
      if (topics[a] == topics[b])
        return make_error("targets.yaml", "bodies '" + bodies[a] + "' and '" + bodies[b] + "'",
                          "both give the ROS 2 topic /" + topics[b].substr(3) +
                              " (outputs.ros2 makes names ROS topic tokens: other "
                              "characters than letters, digits and '_' become '_'); rename one");
  }
  return topics;
}

PoseOut published_pose(const ResultBody& body, const WorldRotation& r) noexcept {
  PoseOut p;
  const auto& t = body.t_world_body_mm;
  if (r.identity) {
    p.t_m = {t[0] * 1e-3, t[1] * 1e-3, t[2] * 1e-3};
    p.q = body.q_world_body;
    return p;
  }
  const auto& R = r.R_frame_world;
  for (std::size_t i = 0; i < 3; ++i)
    p.t_m[i] = (R[3 * i] * t[0] + R[3 * i + 1] * t[1] + R[3 * i + 2] * t[2]) * 1e-3;
  const auto& a = r.q_frame_world;  // Hamilton product q_frame_world * q_world_body
  const auto& b = body.q_world_body;
  p.q = {a[0] * b[0] - a[1] * b[1] - a[2] * b[2] - a[3] * b[3],
         a[0] * b[1] + a[1] * b[0] + a[2] * b[3] - a[3] * b[2],
         a[0] * b[2] - a[1] * b[3] + a[2] * b[0] + a[3] * b[1],
         a[0] * b[3] + a[1] * b[2] - a[2] * b[1] + a[3] * b[0]};
  if (p.q[0] < 0)
    for (double& c : p.q) c = -c;
  return p;
}

TwistOut published_twist(const ResultBody& body, const WorldRotation& r) noexcept {
  TwistOut out;
  const auto& R = r.R_frame_world;
  for (std::size_t i = 0; i < 3; ++i) {
    const auto& v = body.v_world_mm_s;
    const auto& w = body.w_world_rad_s;
    const auto turned = [&](const std::array<float, 3>& x) {
      if (r.identity) return static_cast<double>(x[i]);
      return R[3 * i] * static_cast<double>(x[0]) + R[3 * i + 1] * static_cast<double>(x[1]) +
             R[3 * i + 2] * static_cast<double>(x[2]);
    };
    out.v_m_s[i] = turned(v) * 1e-3;
    out.w_rad_s[i] = turned(w);
  }
  return out;
}

std::uint32_t pack_unlabelled(const FrameResult& frame, const WorldRotation& r,
                              std::uint8_t* data) noexcept {
  std::uint32_t n = 0;
  const int count = std::clamp(frame.point_count, 0, kMaxResultPoints);
  const auto& R = r.R_frame_world;
  for (int i = 0; i < count; ++i) {
    const ResultPoint& p = frame.points[static_cast<std::size_t>(i)];
    if (p.labelled != 0) continue;
    const double x[3] = {p.X_world_mm[0], p.X_world_mm[1], p.X_world_mm[2]};
    float xyz[3];
    for (std::size_t k = 0; k < 3; ++k)
      xyz[k] = static_cast<float>(
          (r.identity ? x[k] : R[3 * k] * x[0] + R[3 * k + 1] * x[1] + R[3 * k + 2] * x[2]) * 1e-3);
    std::memcpy(data + static_cast<std::size_t>(n) * kCloudPointStep, xyz, sizeof xyz);
    ++n;
  }
  return n;
}

}  // namespace mocap::publish::ros2
