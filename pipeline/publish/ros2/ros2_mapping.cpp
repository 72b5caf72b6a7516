// Design: see ros2_mapping.h.
#include "pipeline/publish/ros2/ros2_mapping.h"

#include <time.h>

#include <algorithm>
#include <limits>

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

}  // namespace mocap::publish::ros2
