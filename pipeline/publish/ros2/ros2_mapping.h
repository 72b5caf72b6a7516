// Design: the pure part of the ROS 2 output (no DDS here, so it is tested on its own):
// the /joint_states names of the joint model's degrees of freedom, exactly as the URDF
// of `mocap calibrate --urdf` names its revolute joints (kinematics/urdf_writer.h: a
// hinge J is "J"; a ball J is "J_x", "J_y", "J_z", its Euler angles a0, a1, a2); the
// ROS_DOMAIN_ID parsing (one-line error naming the variable); and the capture-time
// conversion from CLOCK_MONOTONIC to CLOCK_REALTIME with an offset measured at start.
// The 2027-01 additions: the output's settings (outputs.ros2.frame_id and
// world_rotation, one-line errors naming the key), the /mocap/<body>/pose topic names
// (body names made legal ROS topic tokens), the fixed rotation R_frame_world from
// mocap's world to the published frame applied to poses and points (never to joint
// angles, which are relative), and the packing of the unlabelled points into the
// PointCloud2 layout (x, y, z float32, metres, point_step 12).
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "core/expected.h"
#include "formats/joints_yaml.h"
#include "pipeline/publish/capture_clock.h"
#include "pipeline/publish/frame_result.h"

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

// The fixed rotation from mocap's world to the published frame (outputs.ros2.world_rotation).
struct WorldRotation {
  bool identity = true;                               // nothing is turned (the default)
  std::array<double, 4> q_frame_world{{1, 0, 0, 0}};  // qw, qx, qy, qz, unit, qw >= 0
  std::array<double, 9> R_frame_world{{1, 0, 0, 0, 1, 0, 0, 0, 1}};  // row-major
};

// "identity"; "camera_to_z_up" (mocap's world is camera 0's frame, x right, y down, z
// along the view -> x along the view, y left, z up, as REP 103); "y_up_to_z_up" (x, y, z
// with y up -> x, -z, y); or a unit quaternion "qw qx qy qz" (spaces or commas, norm
// within 1e-3 of 1, normalised). Error: "<where>: world_rotation: ...".
Expected<WorldRotation> parse_world_rotation(const std::string& text, const std::string& where);

// The published parent frame (outputs.ros2.frame_id, default "mocap"): 1..256 characters
// of letters, digits, '_', '-', '.', '/', not starting with '/' (tf2 refuses that).
// Error: "<where>: frame_id: ...".
Expected<void> check_frame_id(const std::string& frame_id, const std::string& where);

// A body name as one ROS topic token: every character other than a letter, digit or '_'
// becomes '_', and a leading digit gets a '_' before it ("left arm" -> "left_arm").
std::string topic_token(const std::string& body);
// The DDS topic names "rt/mocap/<token>/pose" of the bodies, in order. Error (naming the
// two bodies) when two names give the same topic.
Expected<std::vector<std::string>> pose_topics(const std::vector<std::string>& bodies);

// A body's pose as published: translation in metres and the quaternion (qw, qx, qy, qz),
// both turned by `r` (the identity leaves the values exactly as they are).
struct PoseOut {
  std::array<double, 3> t_m{};
  std::array<double, 4> q{};
};
PoseOut published_pose(const ResultBody& body, const WorldRotation& r) noexcept;

// A body's velocities as published on /mocap/<body>/twist: the origin's linear velocity
// (m/s) and the angular velocity (rad/s), both in the published frame (turned by `r`).
struct TwistOut {
  std::array<double, 3> v_m_s{};
  std::array<double, 3> w_rad_s{};
};
TwistOut published_twist(const ResultBody& body, const WorldRotation& r) noexcept;

// PointCloud2 layout of mocap's unlabelled points: x, y, z float32 at offsets 0, 4, 8.
inline constexpr std::uint32_t kCloudPointStep = 12;
inline constexpr std::uint8_t kPointFieldFloat32 = 7;  // sensor_msgs/PointField FLOAT32
// Writes the frame's unlabelled points (ResultPoint::labelled == 0) into `data` (room for
// kMaxResultPoints * kCloudPointStep bytes) in metres, turned by `r`, in this machine's
// byte order; returns how many.
std::uint32_t pack_unlabelled(const FrameResult& frame, const WorldRotation& r,
                              std::uint8_t* data) noexcept;

}  // namespace mocap::publish::ros2
