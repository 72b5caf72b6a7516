// Design: the capture time of a frame on the system clock, shared by every output that
// stamps messages with wall-clock time (ROS 2 header.stamp, VRPN message times). Frames
// carry CLOCK_MONOTONIC capture times (FrameResult::joints.capture_ns); an output adds
// the offset CLOCK_REALTIME - CLOCK_MONOTONIC measured once at its setup, so that a
// clock step while running (NTP) does not reorder the published stamps.
#pragma once

#include <cstdint>

namespace mocap::publish {

// CLOCK_REALTIME - CLOCK_MONOTONIC in ns, measured now (the tightest of a few readings).
std::int64_t realtime_offset_ns() noexcept;

}  // namespace mocap::publish
