// Design: THE health view of the live pipeline (one home): what a supervisor (the
// systemd watchdog and status line of pipeline/service), the periodic progress line and
// `mocap run`'s end-of-run fault report read while it runs. PipelineHealth is a value
// read from the stages' atomics (no lock, no allocation); HealthSource is the seam the
// supervisor reads through (Pipeline implements it; tests fake it), with the
// trigger-to-publish histogram for windowed percentiles.
#pragma once

#include <array>
#include <cstdint>

#include "core/camera_set.h"
#include "core/latency_histogram.h"

namespace mocap::pipeline {

// A cheap view of the running pipeline for a supervisor (systemd watchdog, status line):
// health() reads only atomics (no lock, no allocation; ~2 k relaxed loads for p99).
struct PipelineHealth {
  std::uint64_t frames_triggered = 0;
  std::uint64_t frames_published = 0;
  // Triggered frames known to be lost (never published): the sum of the sequence-level
  // drop counters (frames_unpaired + identify_skipped + identify_no_slot + publish_skipped).
  std::uint64_t frames_dropped = 0;
  double fps = 0.0;     // publish rate over the last ~16 frames; 0 after 1 s without one
  double p99_us = 0.0;  // trigger-to-publish p99 since start()
  double max_us = 0.0;  // trigger-to-publish max since start()
  std::int64_t last_publish_ns = 0;  // CLOCK_MONOTONIC; 0: nothing published yet
  int camera_count = 0;              // entries [0, camera_count) of the arrays below
  // Per camera: time since camera c last delivered a frame.
  std::array<std::int64_t, kMaxCameras> camera_silent_ms{};
  // Per camera: frames whose blobs did not all fit (an image full of blobs: the detector's
  // run or blob capacity overflowed; detect_camN_frames_overflow) and camera clock steps
  // (timestamp_backwards_camN + timestamp_jumps_camN).
  std::array<std::uint64_t, kMaxCameras> detect_overflow_frames{};
  std::array<std::uint64_t, kMaxCameras> timestamp_steps{};
  // Summed over the output sinks (OutputCounters): frames a transport refused, and frames
  // a slow sink's drop-oldest queue dropped.
  std::uint64_t output_failures = 0;
  std::uint64_t output_dropped = 0;
};

class HealthSource {
 public:
  virtual ~HealthSource() = default;
  // Any thread.
  virtual PipelineHealth health() const noexcept = 0;
  // The trigger-to-publish histogram (nullptr before the pipeline first started).
  virtual const LatencyHistogram* end_to_end() const noexcept = 0;
};

}  // namespace mocap::pipeline
