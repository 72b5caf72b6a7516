// Design: the one record of a frame's whole result that the publish stage hands to every
// output sink (UDP, iceoryx, ROS 2, Foxglove, ...): the joint angles with validity and
// quality (the public client::JointsMessage), the body poses, the labelled markers and
// the 3D points. Fixed capacity and trivially copyable, so that it lives in preallocated
// publish slots and can be copied into the bounded drop-oldest queue of a slow sink
// without allocation. Each sink encodes what it needs; names (bodies, joints, cameras)
// are given to sinks once at setup (OutputContext in output_sink.h), not per frame.
// Units: millimetres, radians, world frame; a pose maps body to world (X_world = R X_body + t).
#pragma once

#include <array>
#include <cstdint>
#include <type_traits>

#include "client/joints_message.h"

namespace mocap::publish {

inline constexpr int kMaxResultBodies = 16;    // = identify's kMaxBodies
inline constexpr int kMaxResultMarkers = 256;  // labelled markers per frame
inline constexpr int kMaxResultPoints = 256;   // 3D points per frame (= kMaxPoints)

struct ResultBody {
  std::uint8_t found = 0;    // 1: the body was found in this frame
  std::uint8_t markers = 0;  // markers matched
  std::uint8_t reserved[2] = {0, 0};
  float rms_mm = 0.0f;                                     // residual of the fit
  std::array<double, 4> q_world_body{{1.0, 0.0, 0.0, 0.0}};  // qw, qx, qy, qz, qw >= 0
  std::array<double, 3> t_world_body_mm{{0.0, 0.0, 0.0}};
};

struct ResultMarker {
  std::uint8_t body = 0;    // index in targets.yaml
  std::uint8_t marker = 0;  // index in that body's target
  std::uint8_t reserved[2] = {0, 0};
  float residual_mm = 0.0f;                     // |measured - posed model marker|
  std::array<float, 3> X_world_mm{{0, 0, 0}};  // the measured point
};

struct ResultPoint {
  std::array<float, 3> X_world_mm{{0, 0, 0}};
  float reproj_px = 0.0f;
  std::uint8_t cameras = 0;  // how many cameras saw the point
  std::uint8_t reserved[3] = {0, 0, 0};
};

struct FrameResult {
  client::JointsMessage joints;  // sequence, capture/publish time, flags, angles + quality
  std::int32_t body_count = 0;
  std::int32_t marker_count = 0;
  std::int32_t point_count = 0;
  std::array<ResultBody, kMaxResultBodies> bodies{};
  std::array<ResultMarker, kMaxResultMarkers> markers{};
  std::array<ResultPoint, kMaxResultPoints> points{};
};

static_assert(std::is_trivially_copyable_v<FrameResult>, "FrameResult lives in slots");

}  // namespace mocap::publish
