// Design: the pure part of the ROS 2 output (no DDS here, so it is tested on its own):
// the /joint_states names of the joint model's degrees of freedom, exactly as the URDF
// of `mocap calibrate --urdf` names its revolute joints (kinematics/urdf_writer.h: a
// hinge J is "J"; a ball J is "J_x", "J_y", "J_z", its Euler angles a0, a1, a2); the
// ROS_DOMAIN_ID parsing (one-line error naming the variable); and the capture-time
// conversion from CLOCK_MONOTONIC to CLOCK_REALTIME with an offset measured at start.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "core/expected.h"
#include "formats/joints_yaml.h"
#include "pipeline/publish/capture_clock.h"

namespace mocap::publish::ros2 {

struct JointDof {
  std::string name;   // URDF joint name
  int joint = 0;      // index in the model (= JointsMessage::joints index)
  int component = 0;  // 0..2: a[component] of that joint's record
};

// One entry per degree of freedom, in model order (joints beyond `max_joints` left out).
std::vector<JointDof> joint_dofs(const JointModel& model, int max_joints);

// ROS_DOMAIN_ID: unset or empty -> 0; else an integer 0..232 (ROS 2's usable range).
// `value` is the variable's text or null.
Expected<std::uint32_t> parse_domain_id(const char* value);

// CLOCK_REALTIME - CLOCK_MONOTONIC in ns (pipeline/publish/capture_clock.h, shared with VRPN).
using mocap::publish::realtime_offset_ns;

struct Stamp {
  std::int32_t sec = 0;
  std::uint32_t nanosec = 0;  // 0..999'999'999
};
// builtin_interfaces/Time of a CLOCK_MONOTONIC time, given realtime_offset_ns().
Stamp to_stamp(std::int64_t monotonic_ns, std::int64_t offset_ns) noexcept;

}  // namespace mocap::publish::ros2
