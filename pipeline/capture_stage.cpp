// Design: see capture_stage.h.
#include "pipeline/capture_stage.h"

#include <algorithm>

namespace mocap::pipeline {
namespace {

// Raises a high-water-mark counter to `value` (single writer).
void raise_to(rt::Counter& mark, std::uint64_t value) noexcept {
  if (value > mark.get()) mark.add(value - mark.get());
}

}  // namespace

CaptureStage::CaptureStage(StageContext& context, const std::vector<hal::Camera*>& cameras,
                           const std::vector<DetectStage*>& detect, std::int64_t start_ns)
    : context_(context),
      cameras_(cameras),
      detect_(detect),
      camera_count_(static_cast<int>(cameras.size())),
      start_ns_(start_ns) {}

void CaptureStage::release_returned() noexcept {
  for (int c = 0; c < camera_count_; ++c) {
    const auto ci = static_cast<std::size_t>(c);
    hal::Frame f;
    while (detect_[ci]->returned().try_pop(f)) {
      if (cameras_[ci]->release(f) != hal::CameraStatus::kOk) counters_.release_errors.add();
    }
  }
}

void CaptureStage::drain() noexcept {
  for (int c = 0; c < camera_count_; ++c) {
    const auto ci = static_cast<std::size_t>(c);
    hal::Frame f;
    while (detect_[ci]->input().try_pop(f)) cameras_[ci]->release(f);
  }
  release_returned();
}

void CaptureStage::setup_clock_checks(bool triggered_mode, std::int64_t period_ns) noexcept {
  for (std::size_t c = 0; c < static_cast<std::size_t>(camera_count_); ++c) {
    // The frame period of each camera's timestamps.
    const double free_rate_hz = cameras_[c]->config().frame_rate_hz;
    clock_checks_[c] = TimestampCheck(
        !triggered_mode && free_rate_hz > 0.0
            ? static_cast<std::int64_t>(std::min(1e9 / free_rate_hz, 1e15))  // <= 11 days
            : period_ns);
  }
}

void CaptureStage::finish_capture() noexcept {
  // release (in set_capture_done): publishes every frame handed on before.
  context_.set_capture_done(std::min(delivered_end_, ended_end_));
}

bool CaptureStage::tail_pending(std::uint64_t fired) const noexcept {
  const std::uint64_t end = std::min(delivered_end_, ended_end_);
  for (int c = 0; c < camera_count_; ++c) {
    const auto ci = static_cast<std::size_t>(c);
    // Done: its stream ended, it delivered the last set's sequence (one numbering for
    // every camera), or one frame per trigger (cameras with numberings of their own).
    const bool done =
        ended_[ci] || camera_end_[ci] >= end || (fired != 0 && dequeued_[ci] >= fired);
    if (!done) return true;
  }
  return false;
}

void CaptureStage::take_tail(bool triggered_mode, std::uint64_t fired, std::int64_t last_trigger_ns,
                             bool& end_of_stream) noexcept {
  rt::Doorbell& bell = context_.bell(StageId::kCapture);
  const std::int64_t deadline = monotonic_ns() + kLateFrameNs;
  while (!context_.stopping() && tail_pending(fired) && monotonic_ns() < deadline) {
    const std::uint32_t seen = bell.snapshot();
    std::uint64_t last = 0;
    for (int c = 0; c < camera_count_; ++c)
      (void)poll_camera(c, 0, triggered_mode, last_trigger_ns, last, end_of_stream, false);
    if (!tail_pending(fired)) break;
    bell.wait(seen, kLockstepPollNs);
    release_returned();
  }
}

void CaptureStage::wait_retired(std::uint64_t sequence, std::int64_t last_trigger_ns,
                                bool& end_of_stream) noexcept {
  rt::Doorbell& bell = context_.bell(StageId::kCapture);
  const std::int64_t deadline = monotonic_ns() + kLateFrameNs;
  while (!context_.stopping() && context_.retired_plus_one() <= sequence &&
         monotonic_ns() < deadline) {
    const std::uint32_t seen = bell.snapshot();
    if (context_.retired_plus_one() > sequence) break;
    // Frames of this trigger that came after their camera's dequeue timed out (a slow
    // camera, a camera node's round trip): take them now, or the set never completes.
    std::uint64_t last = 0;
    for (int c = 0; c < camera_count_; ++c)
      (void)poll_camera(c, 0, true, last_trigger_ns, last, end_of_stream, false);
    bell.wait(seen, kLockstepPollNs);
    release_returned();
  }
}

bool CaptureStage::wait_first_frame(std::int64_t last_trigger_ns, std::uint64_t& last_sequence,
                                    bool& end_of_stream) noexcept {
  rt::Doorbell& bell = context_.bell(StageId::kCapture);
  const std::int64_t deadline = monotonic_ns() + kLateFrameNs;
  while (!context_.stopping() && !end_of_stream && monotonic_ns() < deadline) {
    const std::uint32_t seen = bell.snapshot();
    bool pushed = false;
    for (int c = 0; c < camera_count_; ++c)
      pushed =
          poll_camera(c, 0, true, last_trigger_ns, last_sequence, end_of_stream, false) || pushed;
    if (pushed) return true;
    bell.wait(seen, kLockstepPollNs);
    release_returned();
  }
  return false;
}

void CaptureStage::run() noexcept {
  context_.loop_start(StageId::kCapture);
  const PipelineOptions& o = context_.options();
  Counters& k = counters_;
  std::array<bool, kMaxCameras> software{};
  std::array<bool, kMaxCameras> ahead{};  // triggered ahead of the instant (trigger_at)
  bool triggered_mode = false, at_instant = false;
  const auto period_ns = static_cast<std::int64_t>(1e9 / o.trigger_rate_hz);
  std::int64_t lead_ns = 0;
  for (int c = 0; c < camera_count_; ++c) {
    const auto ci = static_cast<std::size_t>(c);
    software[ci] = cameras_[ci]->config().trigger == hal::TriggerMode::kSoftware;
    triggered_mode = triggered_mode || software[ci];
    const std::int64_t lead = software[ci] ? cameras_[ci]->trigger_lead_ns() : 0;
    ahead[ci] = lead > 0;
    at_instant = at_instant || (software[ci] && !ahead[ci]);
    lead_ns = std::max(lead_ns, lead);
  }
  // At most half a period ahead, so the previous trigger's frames come first (the
  // configuration bounds node.trigger_lead_us at kMaxTriggerLeadUs, not by the period).
  lead_ns = std::min(lead_ns, period_ns / 2);
  setup_clock_checks(triggered_mode, period_ns);
  std::int64_t next_trigger_ns = monotonic_ns() + lead_ns;  // the first one ahead too
  std::int64_t last_trigger_ns = 0;  // host time of the last software trigger
  bool end_of_stream = false;        // a camera has no more frames (replay)
  std::uint64_t fired = 0;           // triggers of this run
  dequeued_ = {};
  ended_ = {};
  while (!context_.stopping()) {
    release_returned();
    if (end_of_stream ||
        (triggered_mode && o.max_frames != 0 && k.triggered.get() >= o.max_frames)) {
      if (!context_.capture_done()) {
        take_tail(triggered_mode, triggered_mode ? fired : 0, last_trigger_ns, end_of_stream);
        finish_capture();
      }
      rt::Doorbell& bell = context_.bell(StageId::kCapture);
      bell.wait(bell.snapshot(), kIdleWaitNs);
      continue;
    }
    if (triggered_mode) {
      // Both pacings: at most trigger_rate_hz (lockstep may trigger later, never earlier).
      // The cameras with a lead are triggered that long before the instant.
      hal::sleep_until_ns(next_trigger_ns - lead_ns);
      const std::int64_t now = monotonic_ns();
      // How late this trigger is posted (the capture thread was not scheduled in time, or
      // a camera call overran): invisible in the latencies, which start at the trigger.
      raise_to(k.trigger_late_max_us,
               static_cast<std::uint64_t>(
                   std::max<std::int64_t>(now - (next_trigger_ns - lead_ns), 0) / 1000));
      const std::int64_t instant = std::max(next_trigger_ns, now);
      next_trigger_ns += period_ns;
      if (next_trigger_ns < instant) {  // overran a whole period: re-phase, triggers skipped
        k.trigger_overruns.add(static_cast<std::uint64_t>((instant - next_trigger_ns) / period_ns) +
                               1);
        next_trigger_ns = instant + period_ns;
      }
      for (int c = 0; c < camera_count_; ++c) {
        const auto ci = static_cast<std::size_t>(c);
        if (ahead[ci] && cameras_[ci]->trigger_at(instant) != hal::CameraStatus::kOk)
          k.trigger_errors.add();
      }
      if (at_instant && lead_ns > 0) hal::sleep_until_ns(instant);
      for (int c = 0; c < camera_count_; ++c) {
        const auto ci = static_cast<std::size_t>(c);
        if (software[ci] && !ahead[ci] && cameras_[ci]->trigger() != hal::CameraStatus::kOk)
          k.trigger_errors.add();
      }
      last_trigger_ns = instant;
      k.triggered.add();
      ++fired;
    }
    // Wait for each camera's frame at most dequeue_timeout_ms and never past the next
    // trigger (a stalled camera must not delay the others or the trigger), then drain
    // whatever else is ready (a camera that caught up after a stall).
    std::uint64_t last_sequence = 0;
    bool pushed = false;
    for (int c = 0; c < camera_count_; ++c) {
      int timeout_ms = 5;  // free-run: the cameras are polled in turn
      if (triggered_mode) {
        const std::int64_t left_ns = next_trigger_ns - lead_ns - monotonic_ns();
        const std::int64_t left_ms = (left_ns + 999'999) / 1'000'000;  // round up
        timeout_ms = static_cast<int>(std::clamp<std::int64_t>(left_ms, 0, o.dequeue_timeout_ms));
      }
      pushed = poll_camera(c, timeout_ms, triggered_mode, last_trigger_ns, last_sequence,
                           end_of_stream, true) ||
               pushed;
    }
    if (triggered_mode && o.pacing == TriggerPacing::kLockstep) {
      // Lockstep: no trigger before this one's frames (slower than the period: camera
      // nodes over a loaded network) arrived and were retired, each wait bounded.
      if (!pushed && !end_of_stream)
        pushed = wait_first_frame(last_trigger_ns, last_sequence, end_of_stream);
      if (pushed) wait_retired(last_sequence, last_trigger_ns, end_of_stream);
    }
    if (triggered_mode && end_of_stream && !pushed) k.triggers_past_end.add();
  }
  context_.loop_end(StageId::kCapture);
}

bool CaptureStage::poll_camera(int c, int timeout_ms, bool triggered_mode,
                               std::int64_t last_trigger_ns, std::uint64_t& last_sequence,
                               bool& end_of_stream, bool count_timeouts) noexcept {
  Counters& k = counters_;
  const auto ci = static_cast<std::size_t>(c);
  hal::Camera& cam = *cameras_[ci];
  bool pushed = false;
  const int max_frames = cam.config().buffer_count;
  for (int n = 0; n < max_frames; ++n) {
    hal::Frame f;
    const hal::CameraStatus st = cam.dequeue(f, n == 0 ? timeout_ms : 0);
    if (st == hal::CameraStatus::kTimeout || st == hal::CameraStatus::kAgain) {
      if (n == 0 && count_timeouts) k.dequeue_timeouts[ci].add();
      break;
    }
    if (st == hal::CameraStatus::kEndOfStream) {
      // No set can complete from this camera's last frame on (cameras of different
      // lengths: a camera node whose replay restarted).
      ended_end_ = std::min(ended_end_, camera_end_[ci]);
      ended_[ci] = true;
      end_of_stream = true;
      break;
    }
    if (st != hal::CameraStatus::kOk) {
      k.dequeue_errors.add();
      break;
    }
    on_frame_received(c, f, last_trigger_ns);
    ++dequeued_[ci];
    const PipelineOptions& o = context_.options();
    if (o.tap != nullptr) o.tap->on_frame(c, f);
    if (!triggered_mode && c == 0) k.triggered.add();
    last_sequence = f.sequence;
    if (detect_[ci]->passes_through()) {  // blobs detected elsewhere: handed on here
      detect_[ci]->pass(f);
      pushed = true;
      if (cam.release(f) != hal::CameraStatus::kOk) k.release_errors.add();
    } else if (detect_[ci]->input().try_push(f)) {
      pushed = true;
      context_.note_handed_to_detect(c);
      context_.bell(StageId::detect(c)).ring();
    } else {  // the detector holds every slot (stalled): drop this frame
      k.ring_full[ci].add();
      if (cam.release(f) != hal::CameraStatus::kOk) k.release_errors.add();
    }
  }
  return pushed;
}

void CaptureStage::on_frame_received(int camera, const hal::Frame& frame,
                                     std::int64_t trigger_ns) noexcept {
  const auto c = static_cast<std::size_t>(camera);
  const std::int64_t now = monotonic_ns();
  // Camera clock steps: counted only; the frame goes on as the camera stamped it (pairing
  // by sequence ignores timestamps; see docs/pipeline.md, "Camera clock steps").
  switch (clock_checks_[c].check(frame.sequence, frame.timestamp_ns, now, trigger_ns)) {
    case TimestampVerdict::kBackwards:
      counters_.timestamp_backwards[c].add();
      break;
    case TimestampVerdict::kJump:
      counters_.timestamp_jumps[c].add();
      break;
    case TimestampVerdict::kOk:
      break;
  }
  // relaxed: a single writer (this thread); readers only want a recent, untorn time.
  const std::int64_t last = last_frame_ns_[c].load(std::memory_order_relaxed);
  last_frame_ns_[c].store(now, std::memory_order_relaxed);
  if (last != 0)  // between two frames (start-up, before the first frame, excluded)
    raise_to(counters_.max_silence_us[c],
             static_cast<std::uint64_t>(std::max<std::int64_t>(now - last, 0) / 1000));
  context_.note_first_sequence(frame.sequence);
  delivered_end_ = std::max(delivered_end_, frame.sequence + 1);
  camera_end_[c] = std::max(camera_end_[c], frame.sequence + 1);
}

void CaptureStage::report(rt::CounterReport& out) const {
  counters_.group.report(camera_count_, out);
  for (int c = 0; c < camera_count_; ++c) {  // the cameras' own counters
    const hal::CameraCounters& cc = cameras_[static_cast<std::size_t>(c)]->counters();
    out.emplace_back(rt::counter_name("camera_no_buffer_cam#", c), cc.no_buffer.get());
    out.emplace_back(rt::counter_name("camera_dropped_cam#", c), cc.dropped.get());
  }
}

}  // namespace mocap::pipeline
