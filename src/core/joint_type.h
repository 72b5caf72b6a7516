// Design: the one joint type of the whole project: the spec's joints.yaml `type`
// (formats/joints_yaml.h reads and writes it as "ball" | "hinge"), the calibrated model,
// the joint angles, and the public message's JointRecord::type (client/joints_message.h
// names it client::JointKind). The values are the UDP datagram v1 wire values
// (../shared/spec/interfaces.md): never renumber. Installed with the client headers,
// so it depends on nothing but <cstdint>.
#pragma once

#include <cstdint>

namespace mocap {

enum class JointType : std::uint8_t {
  kBall = 0,   // 3 DOF: XYZ Euler angles + quaternion
  kHinge = 1,  // 1 DOF: the angle about the hinge axis
};

}  // namespace mocap
