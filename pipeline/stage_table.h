// Design: THE table of the live pipeline's threads (PX4 style: one place to read and
// tune every thread's CPU, SCHED_FIFO priority and input ring depth). docs/pipeline.md
// documents it; `mocap run --config` may override it per stage. One row per stage
// kind; the detect row is the RULE for the rig's detect stages (one per camera, 2..32):
//   detect stage k: thread "mocap-detect<k>", CPU (row cpu + k) % cpu_count (row cpu -1:
//   not pinned), the row's priority and ring depth, unless a per-camera override
//   (DetectOverride, `pipeline.stages.detect<k>`) sets them.
// On the dual-core capture PC the detectors of a stereo pair thus run on different
// cores, and with N cameras they alternate over both cores; capture has the highest
// priority so it never misses a trigger.
#pragma once

#include <array>
#include <cstdint>
#include <string>

#include "core/camera_set.h"

namespace mocap::pipeline {

enum class StageKind : std::uint8_t { kCapture = 0, kDetect, kIdentify, kPublish };
inline constexpr std::size_t kStageKinds = 4;

// One thread of the pipeline: a stage kind, and for detect stages the camera.
struct StageId {
  StageKind kind = StageKind::kCapture;
  int camera = 0;  // detect stages only

  static constexpr StageId detect(int c) noexcept { return {StageKind::kDetect, c}; }
  static const StageId kCapture, kIdentify, kPublish;
  friend constexpr bool operator==(StageId a, StageId b) noexcept {
    return a.kind == b.kind && (a.kind != StageKind::kDetect || a.camera == b.camera);
  }
};
inline constexpr StageId StageId::kCapture{StageKind::kCapture, 0};
inline constexpr StageId StageId::kIdentify{StageKind::kIdentify, 0};
inline constexpr StageId StageId::kPublish{StageKind::kPublish, 0};

// Threads of a pipeline over kMaxCameras cameras; index(): capture 0, detect k 1 + k,
// identify 1 + kMaxCameras, publish 2 + kMaxCameras (arrays indexed per thread).
inline constexpr std::size_t kMaxStages = 3 + static_cast<std::size_t>(kMaxCameras);
inline constexpr std::size_t index(StageId id) noexcept {
  switch (id.kind) {
    case StageKind::kCapture:
      return 0;
    case StageKind::kDetect:
      return 1 + static_cast<std::size_t>(id.camera);
    case StageKind::kIdentify:
      return 1 + static_cast<std::size_t>(kMaxCameras);
    case StageKind::kPublish:
      return 2 + static_cast<std::size_t>(kMaxCameras);
  }
  return 0;
}

struct StageSpec {
  const char* name;          // thread name (<= 15 characters; detect: + the camera index)
  int cpu;                   // CPU to pin to; -1: not pinned (detect: first CPU of the rule)
  int fifo_priority;         // SCHED_FIFO 1..99; 0: default policy
  std::uint32_t ring_depth;  // capacity of this stage's INPUT ring (slots); capture: unused
};

// capture  : triggers every camera, dequeues, hands frames to the detectors, releases
//            the buffers the detectors give back.
// detect k : blob detection of camera k (input: camera frames, drop-oldest).
// identify : matches the cameras' blob lists by trigger sequence, then pairs + N-view
//            merge + triangulation + identification + joint angles
//            (FrameProcessor::process_blobs) (input: blob slots per camera).
// publish  : sends the frame result to every sink (UDP, iceoryx, ...) (input: message
//            slots, drop-oldest).
inline constexpr std::array<StageSpec, kStageKinds> kDefaultStages = {{
    {"mocap-capture", 0, 80, 0},
    {"mocap-detect", 0, 70, 3},  // the rule: detect k on CPU (0 + k) % cpu_count
    {"mocap-identify", 1, 60, 4},
    {"mocap-publish", 0, 50, 4},
}};

// A per-camera override of the detect rule (unset fields: the rule's value).
struct DetectOverride {
  static constexpr int kUnset = -2;
  int cpu = kUnset;              // -1: not pinned
  int fifo_priority = kUnset;    // 0..99
  std::uint32_t ring_depth = 0;  // 0: unset
};

struct StageTable {
  std::array<StageSpec, kStageKinds> rows = kDefaultStages;
  std::array<DetectOverride, kMaxCameras> detect{};

  StageSpec& operator[](StageKind k) noexcept { return rows[static_cast<std::size_t>(k)]; }
  const StageSpec& operator[](StageKind k) const noexcept {
    return rows[static_cast<std::size_t>(k)];
  }
};

// One thread's resolved settings (setup time).
struct ResolvedStage {
  std::string name;  // "mocap-detect3"
  int cpu = -1;
  int fifo_priority = 0;
  std::uint32_t ring_depth = 0;
};

// The table's rule applied to stage `id` on a machine with `cpu_count` CPUs (>= 1).
inline ResolvedStage resolve_stage(const StageTable& t, StageId id, int cpu_count) {
  const StageSpec& row = t[id.kind];
  ResolvedStage r{row.name, row.cpu, row.fifo_priority, row.ring_depth};
  if (id.kind != StageKind::kDetect) return r;
  r.name += std::to_string(id.camera);
  if (row.cpu >= 0) r.cpu = (row.cpu + id.camera) % (cpu_count > 0 ? cpu_count : 1);
  const DetectOverride& o = t.detect[static_cast<std::size_t>(id.camera)];
  if (o.cpu != DetectOverride::kUnset) r.cpu = o.cpu;
  if (o.fifo_priority != DetectOverride::kUnset) r.fifo_priority = o.fifo_priority;
  if (o.ring_depth != 0) r.ring_depth = o.ring_depth;
  return r;
}

}  // namespace mocap::pipeline
