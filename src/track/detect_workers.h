// Design: the offline tracker's detection on two cores, as the live pipeline detects
// (one detect stage per camera, spread over the cores; pipeline/stage_table.h). A
// persistent worker thread and the calling thread take the cameras of a frame one at a
// time from a shared counter, so a worker that wakes late (a futex wake-up on a loaded
// machine can take a millisecond) only leaves more cameras to the caller instead of
// delaying the frame; the frame's other stages (correspondence, triangulation,
// identification, angles) then run on the calling thread. The output is exactly
// FrameProcessor::process's: every camera has its own detector and blob list, and
// detect_camera() is thread-safe between different cameras. The thread that detects a
// camera also undistorts its blobs (FrameProcessor::undistort_camera, stage 2's first
// step, bit for bit), so the calling thread's stage 2 starts from them.
// Per frame: the caller rings posted_ (rt::Doorbell: a futex with a timeout, no lock),
// then publishes the frame and a generation-tagged camera counter
// (next_: generation << 32 | next camera); each thread claims a camera by compare-exchange
// of next_ (a stale worker sees another generation or no camera left and claims nothing);
// completed_ counts the cameras detected, and the caller returns when it reaches the
// camera count (the thread that completes the last camera rings done_), so the frame's
// views stay valid for every claim. Every sleep is bounded (kWaitNs): a wake-up that were
// ever lost costs one timeout, never a hang. No allocation after
// construction. Timings are wall-clock, as in process(): `detect` is the time until
// every camera of the frame was detected.
// Wake-ups off the frame's time: warm() (called before the frame's files are read) rings
// the worker early; it then spins for the frame's generation for up to kWarmSpinNs (then
// sleeps again), so its wake-up overlaps the reading instead of leaving its cameras to
// the caller. The caller, out of cameras, spins for the worker's last one for up to
// kFinishSpinNs (a few cameras' detection) before it sleeps. Both spins only take a core
// that the frame leaves idle.
#pragma once

#include <atomic>
#include <cstdint>
#include <span>
#include <thread>

#include "rt/doorbell.h"
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
  // A frame follows soon (its files are being read): the worker wakes now.
  void warm() noexcept;
  // FrameProcessor::process with the detection split over the two threads.
  bool process(std::span<const ImageView* const> views, std::int64_t timestamp_ns,
               FrameOutput& out) noexcept;

 private:
  // Claims and detects cameras of generation `gen` until none is left.
  void detect_claimed(std::uint32_t gen) noexcept;
  void run() noexcept;

  static constexpr std::int64_t kWarmSpinNs = 20'000'000;  // longer than a frame's reading
  static constexpr std::int64_t kFinishSpinNs = 500'000;   // a few cameras' detection
  static constexpr std::int64_t kWaitNs = 10'000'000;      // a sleep's safety net

  FrameProcessor& proc_;
  // The frame in hand: written by the caller before next_'s release store, read by a
  // thread after its acquire compare-exchange of next_ claimed one of its cameras.
  std::span<const ImageView* const> views_;
  FrameOutput* out_ = nullptr;
  std::atomic<std::uint64_t> next_{0};       // generation << 32 | next camera to claim
  std::uint32_t generation_ = 0;             // the caller's last frame
  rt::Doorbell posted_;                      // the worker's: frames, warm() and stop
  rt::Doorbell done_;                        // the caller's: the frame's last camera
  std::atomic<std::uint32_t> completed_{0};  // cameras of this generation detected
  std::atomic<bool> stop_{false};
  std::thread worker_;
};

}  // namespace mocap
