// Design: how the live pipeline is set up: its options (stage table, trigger pacing,
// frame matching) and the seams through which tests and `mocap record` watch it
// (FrameObserver, FrameTap, StageHooks). Every stage sees these options read-only; the
// stage objects (capture_stage.h, detect_stage.h, identify_stage.h, publish_stage.h)
// and the Pipeline that wires them (pipeline.h) include this header.
#pragma once

#include <array>
#include <cstdint>

#include "core/capture_modes.h"
#include "hal/camera.h"
#include "pipeline/stage_table.h"
#include "track/frame_processor.h"

namespace mocap::pipeline {

using mocap::TriggerPacing;  // core/capture_modes.h

enum class PairBy : std::uint8_t {
  kSequence,   // trigger sequence numbers must match (triggered cameras)
  kTimestamp,  // sensor timestamps within pair_tolerance_us (free-running cameras)
};

// Called on the identify thread with every processed frame (tests, recording).
class FrameObserver {
 public:
  virtual ~FrameObserver() = default;
  virtual void observe(std::uint64_t sequence, std::int64_t capture_ns,
                       const FrameOutput& out) noexcept = 0;
};

// Called on the capture thread with every frame a camera delivered (missing replay frames
// included), right after it was dequeued and before it goes to its detector: `mocap
// record` copies the images here (pipeline/record). Must be noexcept, allocation-free and
// return quickly (periodic pacing: it must never wait; lockstep pacing may wait briefly,
// as the trigger does).
class FrameTap {
 public:
  virtual ~FrameTap() = default;
  virtual void on_frame(int camera, const hal::Frame& frame) noexcept = 0;
};

// Called on each camera's detect thread with every frame it detected, right after the
// detection and before the image goes back to the camera: `mocap record --blobs` copies
// the blob list (and every Nth image) here (pipeline/record). Must be noexcept,
// allocation-free and return quickly (lockstep pacing may wait briefly). `present`:
// false when the camera's frame was missing (blobs then empty).
class BlobTap {
 public:
  virtual ~BlobTap() = default;
  virtual void on_blobs(int camera, const hal::Frame& frame, bool present,
                        const detect::BlobList& blobs) noexcept = 0;
};

// Called on each stage thread right before its loop starts and right after it ends
// (tests count the thread's heap allocations in between).
class StageHooks {
 public:
  virtual ~StageHooks() = default;
  virtual void on_loop_start(StageId stage) noexcept = 0;
  virtual void on_loop_end(StageId stage) noexcept = 0;
};

struct PipelineOptions {
  StageTable stages{};      // the rule per stage kind + per-camera detect overrides
  int cpu_count = 0;        // CPUs the detect rule spreads over; 0: this machine's (online)
  bool realtime = true;     // apply the table's CPU pinning and SCHED_FIFO (fallback noted)
  bool lock_memory = true;  // mlockall (fallback noted)
  // PM QoS CPU latency limit held while running (rt/cpu_latency.h, fallback noted): 0
  // keeps idle CPUs polling, so a stage woken by its doorbell runs without an idle-state
  // exit; -1: no request (the kernel's idle governor decides).
  int cpu_latency_us = 0;
  double trigger_rate_hz = 100.0;  // software-triggered cameras
  TriggerPacing pacing = TriggerPacing::kPeriodic;
  std::uint64_t max_frames = 0;  // stop triggering after this many (0: unlimited)
  // Longest wait for a triggered frame; the capture also never waits past the next
  // trigger, so a stalled camera cannot slow the other one down.
  int dequeue_timeout_ms = 20;
  PairBy pair_by = PairBy::kSequence;
  // kTimestamp only: two frames pair when their timestamps differ by at most this; must
  // be below half the frame period.
  std::int64_t pair_tolerance_us = 1000;
  // Per camera (hal::FramePairer): how long (ns) the other cameras' frames wait for its
  // frame before it counts as silent and the sets go on without it (pair_silent_cam#,
  // pair_absent_cam#, frames_without_silent_cameras); 0: always waited for. Set for the
  // camera-node cameras the central does not trigger (service::pipeline_options).
  std::array<std::int64_t, kMaxCameras> silent_after_ns{};
  bool has_silent_bounds() const noexcept {
    for (const std::int64_t b : silent_after_ns) {
      if (b > 0) return true;
    }
    return false;
  }
  FrameObserver* observer = nullptr;
  StageHooks* hooks = nullptr;
  FrameTap* tap = nullptr;      // `mocap record`: every delivered frame, capture thread
  BlobTap* blob_tap = nullptr;  // `mocap record --blobs`: every detected frame, detect threads
  // Catch-up (`pipeline.catch_up_ms`): a stage that finds newer items waiting still takes
  // the oldest while it is at most catch_up_ns old (since its latency origin: the trigger,
  // or a replay's delivery), in order; an older one is skipped (detect#_skipped,
  // identify_skipped, publish_skipped). So a stall the pipeline can make up (the machine,
  // a slow output) delays a few frames instead of dropping them, and a stage that cannot
  // keep up sheds the frames too old to matter to a controller. 0: always the newest.
  std::int64_t catch_up_ns = 25'000'000;
  // true (`mocap record --blobs`, `pipeline.every_frame`): every stage works on every
  // frame in order, however old (no detect#_skipped, identify_skipped or publish_skipped):
  // a stall shorter than the rings' depth delays frames and loses none. A stage that falls
  // behind for longer fills its input ring and the producer drops there
  // (capture_dropped_cam#, detect#_no_slot, identify_no_slot).
  bool every_frame = false;
  // Whether a stage takes an item with this latency origin at now_ns although a newer
  // one waits.
  bool fresh(std::int64_t origin_ns, std::int64_t now_ns) const noexcept {
    return every_frame || now_ns - origin_ns <= catch_up_ns;
  }
};

}  // namespace mocap::pipeline
