// Design: the offline tracker's detection on two cores, as the live pipeline detects
// (one detect stage per camera, spread over the cores; pipeline/stage_table.h). A
// persistent worker thread detects the odd cameras of a frame while the calling thread
// detects the even ones; the frame's other stages (correspondence, triangulation,
// identification, angles) then run on the calling thread. The output is exactly
// FrameProcessor::process's: every camera has its own detector and blob list, and
// detect_camera() is thread-safe between different cameras.
// One handshake per frame through two 32-bit counters (C++20 atomic wait/notify: a futex
// on int-sized atomics, no lock; no allocation after construction; the counters wrap and
// are only compared for equality). Timings are wall-clock, as in process(): `detect` is
// the time until every camera of the frame was detected.
#pragma once

#include <atomic>
#include <cstdint>
#include <span>
#include <thread>

#include "track/frame_processor.h"

namespace mocap {

class ParallelDetect {
 public:
  // Starts the worker. proc must outlive this object.
  explicit ParallelDetect(FrameProcessor& proc);
  ~ParallelDetect();
  ParallelDetect(const ParallelDetect&) = delete;
  ParallelDetect& operator=(const ParallelDetect&) = delete;

  // Stage 1 alone (out.blobs, out.camera_present, out.times.detect), split over the two
  // threads; the caller then runs FrameProcessor::process_blobs.
  void detect(std::span<const ImageView* const> views, FrameOutput& out) noexcept;
  // FrameProcessor::process with the detection split over the two threads.
  bool process(std::span<const ImageView* const> views, std::int64_t timestamp_ns,
               FrameOutput& out) noexcept;

 private:
  void detect_share(int first_camera) noexcept;  // cameras first, first + 2, ...
  void run() noexcept;

  FrameProcessor& proc_;
  // The frame in hand: written by the caller before posted_'s release increment, read
  // by the worker after its acquire load.
  std::span<const ImageView* const> views_;
  FrameOutput* out_ = nullptr;
  std::atomic<std::uint32_t> posted_{0};  // frames handed to the worker
  std::atomic<std::uint32_t> done_{0};    // frames whose odd cameras the worker detected
  std::atomic<bool> stop_{false};
  std::thread worker_;
};

}  // namespace mocap
