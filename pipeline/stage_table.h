// Design: THE table of the live pipeline's threads (PX4 style: one place to read and
// tune every thread's CPU, SCHED_FIFO priority and input ring depth). docs/pipeline.md
// documents it; `mocap run --config` may override it per stage. On the dual-core
// capture PC the two detectors run on different cores so both cameras' images are
// searched in parallel; capture has the highest priority so it never misses a trigger.
#pragma once

#include <array>
#include <cstdint>

namespace mocap::pipeline {

enum class StageId : std::uint8_t { kCapture = 0, kDetect0, kDetect1, kIdentify, kPublish };
inline constexpr std::size_t kStageCount = 5;

struct StageSpec {
  const char* name;          // thread name (<= 15 characters)
  int cpu;                   // CPU to pin to; -1: not pinned
  int fifo_priority;         // SCHED_FIFO 1..99; 0: default policy
  std::uint32_t ring_depth;  // capacity of this stage's INPUT ring (slots); capture: unused
};

// capture  : triggers both cameras, dequeues, hands frames to the detectors, releases
//            the buffers the detectors give back.
// detect0/1: blob detection of one camera (input: camera frames, drop-oldest).
// identify : pairs the two cameras' blob lists by trigger sequence, then stereo +
//            triangulation + identification + joint angles (FrameProcessor::process_blobs)
//            (input: blob slots per camera).
// publish  : sends the JointsMessage to every sink (UDP, iceoryx) (input: message slots,
//            drop-oldest).
inline constexpr std::array<StageSpec, kStageCount> kDefaultStages = {{
    {"mocap-capture", 0, 80, 0},
    {"mocap-detect0", 0, 70, 3},
    {"mocap-detect1", 1, 70, 3},
    {"mocap-identify", 1, 60, 4},
    {"mocap-publish", 0, 50, 4},
}};

inline constexpr std::size_t index(StageId id) noexcept { return static_cast<std::size_t>(id); }

}  // namespace mocap::pipeline
