// Design: the capture stage (one thread, the highest priority of the stage table). It
// drives the rig's cameras: fires the software triggers on their grid (absolute
// deadlines; lockstep pacing waits for the previous frame to be retired; a camera with a
// trigger lead, a camera node's, gets trigger_at(instant) that long ahead), dequeues every
// camera without ever waiting on a stalled one past the next trigger, counts each
// camera's clock steps (timestamp_check.h; the frame goes on unchanged), offers each
// frame to the FrameTap (`mocap record`), hands it to its camera's detect stage (dropped
// when the detector holds every slot: capture_dropped_cam#; a camera that delivers blobs,
// a camera node's, is handed on here through DetectStage::pass) and releases the buffers the
// detect stages give back. It alone calls the cameras' release(), so every camera buffer
// has one owner thread. A camera's end of stream (a replayed recording's last frame was
// delivered) ends the triggering, as max_frames does; the capture then takes the last
// triggers' late frames (the tail, bounded by 1 s) and declares its end
// (StageContext::set_capture_done: the frame ledger that ends the run). It owns no ring: each
// detect stage owns its input and return rings; the capture holds their producer and consumer ends.
// run() is the hot path: noexcept, allocation-free, lock-free, no logging; the only syscalls are
// the cameras' trigger/dequeue/release and the trigger clock's sleep. Lockstep pacing waits (each
// wait bounded by 1 s) for the last trigger's first frame and then for it to be retired, polling
// the cameras every millisecond, so a frame that came after its camera's dequeue timed out
// (a camera node's round trip) still completes its set and no trigger runs ahead of it.
#pragma once

#include <array>
#include <atomic>
#include <cstdint>
#include <vector>

#include "hal/camera.h"
#include "pipeline/detect_stage.h"
#include "pipeline/stage_context.h"
#include "pipeline/timestamp_check.h"
#include "rt/counter_group.h"

namespace mocap::pipeline {

class CaptureStage {
 public:
  // cameras (2..kMaxCameras) and detect stages (one per camera, same order) outlive it.
  CaptureStage(StageContext& context, const std::vector<hal::Camera*>& cameras,
               const std::vector<DetectStage*>& detect, std::int64_t start_ns);

  void run() noexcept;  // the thread's body, until the context stops
  // After every thread was joined: every camera buffer still in a ring back to its camera.
  void drain() noexcept;

  // Any thread.
  std::uint64_t triggered() const noexcept { return counters_.triggered.get(); }
  // Time since camera c's last frame (since the start before its first one).
  std::int64_t camera_silent_ns(int camera, std::int64_t now_ns) const noexcept {
    // relaxed: a single writer (this stage); readers only want a recent, untorn time.
    const std::int64_t last =
        last_frame_ns_[static_cast<std::size_t>(camera)].load(std::memory_order_relaxed);
    return now_ns - (last != 0 ? last : start_ns_);
  }
  // Camera c's clock steps (backwards + jumps).
  std::uint64_t timestamp_steps(int camera) const noexcept {
    const auto c = static_cast<std::size_t>(camera);
    return counters_.timestamp_backwards[c].get() + counters_.timestamp_jumps[c].get();
  }
  void report(rt::CounterReport& out) const;  // report time

 private:
  void release_returned() noexcept;
  // trigger_ns: host time of the last software trigger (0: free-running cameras).
  void on_frame_received(int camera, const hal::Frame& frame, std::int64_t trigger_ns) noexcept;
  void setup_clock_checks(bool triggered_mode, std::int64_t period_ns) noexcept;
  // Lockstep: waits (bounded) until `sequence` was retired, polling the cameras meanwhile.
  void wait_retired(std::uint64_t sequence, std::int64_t last_trigger_ns,
                    bool& end_of_stream) noexcept;
  // Lockstep, when no camera delivered within the trigger's dequeue pass: polls the
  // cameras (bounded) until one delivers; true when a frame was pushed.
  bool wait_first_frame(std::int64_t last_trigger_ns, std::uint64_t& last_sequence,
                        bool& end_of_stream) noexcept;
  // Dequeues camera c (the first call waits up to timeout_ms) and hands its frames to its
  // detector; true when a frame was pushed. count_timeouts: an empty first dequeue counts
  // in dequeue_timeouts_cam# (not for the polls while lockstep waits).
  bool poll_camera(int c, int timeout_ms, bool triggered_mode, std::int64_t last_trigger_ns,
                   std::uint64_t& last_sequence, bool& end_of_stream, bool count_timeouts) noexcept;

  // A frame later than this after its trigger is lost (lockstep's waits, the tail).
  static constexpr std::int64_t kLateFrameNs = 1'000'000'000;
  static constexpr std::int64_t kLockstepPollNs = 1'000'000;  // cameras polled while waiting

  StageContext& context_;
  const std::vector<hal::Camera*> cameras_;
  const std::vector<DetectStage*> detect_;
  const int camera_count_;
  const std::int64_t start_ns_;
  std::array<TimestampCheck, kMaxCameras> clock_checks_{};  // this thread (set in run())
  std::array<std::atomic<std::int64_t>, kMaxCameras> last_frame_ns_{};  // this thread writes
  // The capture's end (StageContext::set_capture_done): no frame is handed on after it.
  void finish_capture() noexcept;
  // The last triggers' frames that came after their dequeue pass (a slow camera): taken
  // until every camera delivered its last one or ended, for at most kLateFrameNs, so that
  // the last sets complete. fired: the triggers of this run (0: free-running cameras).
  void take_tail(bool triggered_mode, std::uint64_t fired, std::int64_t last_trigger_ns,
                 bool& end_of_stream) noexcept;
  bool tail_pending(std::uint64_t fired) const noexcept;
  std::uint64_t delivered_end_ = 0;  // highest sequence dequeued + 1 (this thread)
  std::array<std::uint64_t, kMaxCameras> camera_end_{};  // the same per camera (this thread)
  // The lowest camera_end_ of the cameras that reached their end of stream (this thread).
  std::uint64_t ended_end_ = ~std::uint64_t{0};
  std::array<std::uint64_t, kMaxCameras> dequeued_{};  // frames per camera, this run (this thread)
  std::array<bool, kMaxCameras> ended_{};  // the camera's stream ended, this run (this thread)

  struct alignas(64) Counters {
    rt::CounterGroup group;
    rt::NamedCounter triggered{group, "triggered"};
    rt::NamedCounter trigger_errors{group, "trigger_errors"};
    // triggers no camera answered because the source ended (a replay's or a node's end of
    // stream): not frames, so not losses (mocap record's accounting)
    rt::NamedCounter triggers_past_end{group, "triggers_past_end"};
    rt::NamedCounter trigger_overruns{group, "trigger_overruns"};        // periods skipped (late)
    rt::NamedCounter trigger_late_max_us{group, "trigger_late_max_us"};  // vs its deadline
    rt::CameraCounters dequeue_timeouts{group, "dequeue_timeouts_cam#"};
    rt::CameraCounters max_silence_us{group, "camera_max_silence_us_cam#"};  // between frames
    rt::NamedCounter dequeue_errors{group, "dequeue_errors"};
    rt::NamedCounter release_errors{group, "release_errors"};
    rt::CameraCounters ring_full{group, "capture_dropped_cam#"};  // detector held every slot
    rt::CameraCounters timestamp_backwards{group, "timestamp_backwards_cam#"};
    rt::CameraCounters timestamp_jumps{group, "timestamp_jumps_cam#"};
  } counters_;
};

}  // namespace mocap::pipeline
