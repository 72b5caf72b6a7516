// Design: see pipeline.h. The capture stage (hot path: noexcept, allocation-free,
// lock-free, no logging; its counters have this thread as their only writer): fires the
// software triggers on their grid, dequeues every camera without ever waiting on a
// stalled one past the next trigger, counts each camera's clock steps (timestamp_check.h;
// the frame goes on unchanged), hands each frame to its detector (dropping it when the
// detector holds every slot) and releases the buffers the detectors give back.
#include <algorithm>

#include "pipeline/pipeline.h"

namespace mocap::pipeline {

void Pipeline::release_returned() noexcept {
  for (int c = 0; c < camera_count(); ++c) {
    hal::Frame f;
    while (returned_[static_cast<std::size_t>(c)]->try_pop(f)) {
      if (cameras_[static_cast<std::size_t>(c)]->release(f) != hal::CameraStatus::kOk)
        counters_->release_errors.add();
    }
  }
}

void Pipeline::capture_loop() noexcept {
  if (options_.hooks) options_.hooks->on_loop_start(StageId::kCapture);
  Counters& k = *counters_;
  const int cams = camera_count();
  bool software[kMaxCameras] = {};
  bool triggered_mode = false;
  for (int c = 0; c < cams; ++c) {
    software[c] =
        cameras_[static_cast<std::size_t>(c)]->config().trigger == hal::TriggerMode::kSoftware;
    triggered_mode = triggered_mode || software[c];
  }
  const auto period_ns = static_cast<std::int64_t>(1e9 / options_.trigger_rate_hz);
  for (std::size_t c = 0; c < static_cast<std::size_t>(cams);
       ++c) {  // frame period of each camera's timestamps
    const double free_rate_hz = cameras_[c]->config().frame_rate_hz;
    clock_checks_[c] = TimestampCheck(
        !triggered_mode && free_rate_hz > 0.0
            ? static_cast<std::int64_t>(std::min(1e9 / free_rate_hz, 1e15))  // <= 11 days
            : period_ns);
  }
  std::int64_t next_trigger_ns = monotonic_ns();
  std::int64_t last_trigger_ns = 0;  // host time of the last software trigger
  while (!stopping()) {
    release_returned();
    if (triggered_mode) {
      if (options_.max_frames != 0 && k.triggered.get() >= options_.max_frames) {
        // release: finished() (acquire) then sees every counter written before.
        triggering_done_.store(true, std::memory_order_release);
        const std::uint32_t seen = bells_[index(StageId::kCapture)].snapshot();
        bells_[index(StageId::kCapture)].wait(seen, kIdleWaitNs);
        continue;
      }
      // Both pacings: at most trigger_rate_hz (lockstep may trigger later, never earlier).
      hal::sleep_until_ns(next_trigger_ns);
      const std::int64_t now = monotonic_ns();
      // How late this trigger fires (the capture thread was not scheduled in time, or a
      // camera call overran): invisible in the latencies, which start at the trigger.
      const auto late_us =
          static_cast<std::uint64_t>(std::max<std::int64_t>(now - next_trigger_ns, 0) / 1000);
      if (late_us > k.trigger_late_max_us.get())
        k.trigger_late_max_us.add(late_us - k.trigger_late_max_us.get());
      next_trigger_ns += period_ns;
      if (next_trigger_ns < now) {  // overran a whole period: re-phase, triggers skipped
        k.trigger_overruns.add(static_cast<std::uint64_t>((now - next_trigger_ns) / period_ns) + 1);
        next_trigger_ns = now + period_ns;
      }
      for (int c = 0; c < cams; ++c) {
        if (software[c] &&
            cameras_[static_cast<std::size_t>(c)]->trigger() != hal::CameraStatus::kOk)
          k.trigger_errors.add();
      }
      last_trigger_ns = now;
      k.triggered.add();
    }
    // Wait for each camera's frame at most dequeue_timeout_ms and never past the next
    // trigger (a stalled camera must not delay the others or the trigger), then drain
    // whatever else is ready (a camera that caught up after a stall).
    std::uint64_t last_sequence = 0;
    bool pushed = false;
    for (int c = 0; c < cams; ++c) {
      hal::Camera& cam = *cameras_[static_cast<std::size_t>(c)];
      int timeout_ms = 5;  // free-run: the cameras are polled in turn
      if (triggered_mode) {
        const std::int64_t left_ns = next_trigger_ns - monotonic_ns();
        const std::int64_t left_ms = (left_ns + 999'999) / 1'000'000;  // round up
        timeout_ms =
            static_cast<int>(std::clamp<std::int64_t>(left_ms, 0, options_.dequeue_timeout_ms));
      }
      const int max_frames = cam.config().buffer_count;
      for (int n = 0; n < max_frames; ++n) {
        hal::Frame f;
        const hal::CameraStatus st = cam.dequeue(f, n == 0 ? timeout_ms : 0);
        if (st == hal::CameraStatus::kTimeout || st == hal::CameraStatus::kAgain) {
          if (n == 0) k.dequeue_timeouts[c].add();
          break;
        }
        if (st == hal::CameraStatus::kEndOfStream) {
          triggering_done_.store(true, std::memory_order_release);  // see above
          break;
        }
        if (st != hal::CameraStatus::kOk) {
          k.dequeue_errors.add();
          break;
        }
        on_frame_received(c, f, last_trigger_ns);
        if (options_.tap != nullptr) options_.tap->on_frame(c, f);
        if (!triggered_mode && c == 0) k.triggered.add();
        last_sequence = f.sequence;
        if (to_detect_[static_cast<std::size_t>(c)]->try_push(f)) {
          pushed = true;
          bells_[index(StageId::detect(c))].ring();
        } else {  // the detector holds every slot (stalled): drop this frame
          k.capture_ring_full[c].add();
          if (cam.release(f) != hal::CameraStatus::kOk) k.release_errors.add();
        }
      }
    }
    if (pushed && triggered_mode && options_.pacing == TriggerPacing::kLockstep) {
      const std::int64_t deadline = monotonic_ns() + kLockstepTimeoutNs;
      // acquire: pairs with retire()'s release.
      while (!stopping() && retired_.load(std::memory_order_acquire) <= last_sequence &&
             monotonic_ns() < deadline) {
        const std::uint32_t seen = bells_[index(StageId::kCapture)].snapshot();
        if (retired_.load(std::memory_order_acquire) > last_sequence) break;
        bells_[index(StageId::kCapture)].wait(seen, kIdleWaitNs);
        release_returned();
      }
    }
  }
  if (options_.hooks) options_.hooks->on_loop_end(StageId::kCapture);
}

void Pipeline::on_frame_received(int camera, const hal::Frame& frame,
                                 std::int64_t trigger_ns) noexcept {
  const auto c = static_cast<std::size_t>(camera);
  const std::int64_t now = monotonic_ns();
  // Camera clock steps: counted only; the frame goes on as the camera stamped it (pairing
  // by sequence ignores timestamps; see docs/pipeline.md, "Camera clock steps").
  switch (clock_checks_[c].check(frame.sequence, frame.timestamp_ns, now, trigger_ns)) {
    case TimestampVerdict::kBackwards:
      counters_->timestamp_backwards[c].add();
      break;
    case TimestampVerdict::kJump:
      counters_->timestamp_jumps[c].add();
      break;
    case TimestampVerdict::kOk:
      break;
  }
  // relaxed: a single writer (capture); readers only want a recent, untorn time.
  const std::int64_t last = last_frame_ns_[c].load(std::memory_order_relaxed);
  last_frame_ns_[c].store(now, std::memory_order_relaxed);
  if (last != 0) {  // between two frames (start-up, before the first frame, excluded)
    rt::Counter& max_silence = counters_->camera_max_silence_us[c];
    const auto silent_us = static_cast<std::uint64_t>(std::max<std::int64_t>(now - last, 0) / 1000);
    if (silent_us > max_silence.get()) max_silence.add(silent_us - max_silence.get());
  }
  if (first_sequence_.load(std::memory_order_relaxed) == 0) {
    // release: published before this frame enters any ring; identify reads it after
    // receiving a later frame through the rings (acquire), so it sees the value.
    first_sequence_.store(frame.sequence + 1, std::memory_order_release);
  }
}

}  // namespace mocap::pipeline
