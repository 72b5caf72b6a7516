// Design: a frame's VRPN tracker reports, encoded once per frame and copied to every
// client (vrpn_server.cpp). One tracker per body (sender id = the body's index in
// targets.yaml, named as the body), sensor 0:
//   - Pos_Quat for every body found: position = t_world_body / 1000 (metres, mocap's
//     world frame), quaternion q_world_body reordered from (w, x, y, z) to VRPN's
//     (x, y, z, w);
//   - Velocity when the body's velocity_valid is set: vel = v_world / 1000 (m/s, world
//     frame); vel_quat = the rotation exp(w_world dt / 2) of the angular velocity over
//     vel_quat_dt = dt (the frame period), (x, y, z, w).
// Every message's time is the frame's capture time on the system clock. No allocation.
#pragma once

#include <cstddef>
#include <cstdint>

#include "pipeline/publish/frame_result.h"
#include "pipeline/publish/vrpn/vrpn_wire.h"

namespace mocap::publish::vrpn {

// Our type ids (described to every client on connecting, in this order).
inline constexpr std::int32_t kTypePosQuat = 0, kTypeVelocity = 1, kTypePing = 2, kTypePong = 3;
inline constexpr std::string_view kOurTypes[] = {kPosQuatType, kVelocityType, kPingType, kPongType};
// The most bytes one body adds to a frame.
inline constexpr std::size_t kReportBytes =
    message_bytes(kPosQuatPayloadBytes) + message_bytes(kVelocityPayloadBytes);

// The reports of bodies [0, n_bodies) of `frame` into out[0, cap) (cap >= n_bodies *
// kReportBytes for all of them); `sequence` numbers the messages; `reports` counts them.
// Bytes written.
std::size_t encode_frame_reports(const FrameResult& frame, std::size_t n_bodies, double dt_s,
                                 WireTime time, std::uint32_t& sequence, std::uint8_t* out,
                                 std::size_t cap, std::uint64_t& reports) noexcept;

}  // namespace mocap::publish::vrpn
