// Design: see replay_camera.h. Waiting uses clock_nanosleep on CLOCK_MONOTONIC with
// an absolute deadline (no drift over a long replay).
#include "hal/replay_camera.h"

#include <algorithm>
#include <ctime>

namespace mocap::hal {
namespace {

constexpr int kMaxReplayBuffers = 32;

}  // namespace

Expected<std::unique_ptr<ReplayCamera>> ReplayCamera::open(
    std::shared_ptr<const Recording> recording, int camera_index, ReplayPacing pacing) {
  if (!recording) return make_error("replay", "", "no recording");
  if (recording->has_blobs())  // blobs/<camera>.blobs: nothing to deliver as images
    return make_error(recording->dir(), "blobs",
                      "a blob recording holds blob lists, not images: a replay camera needs "
                      "an image recording (track, calibrate and discover read blob recordings)");
  const int n = static_cast<int>(recording->rig().cameras.size());
  if (camera_index < 0 || camera_index >= n) {
    return make_error(
        recording->dir(), "camera",
        "index " + std::to_string(camera_index) + " outside 0.." + std::to_string(n - 1));
  }
  return std::unique_ptr<ReplayCamera>(
      new ReplayCamera(std::move(recording), camera_index, pacing));
}

ReplayCamera::ReplayCamera(std::shared_ptr<const Recording> recording, int camera_index,
                           ReplayPacing pacing)
    : recording_(std::move(recording)), camera_index_(camera_index), pacing_(pacing) {
  name_ = "replay:" + recording_->dir() + "/" +
          recording_->rig().cameras[static_cast<std::size_t>(camera_index)].name;
}

CameraConfig ReplayCamera::native_config() const {
  const CameraModel& m = recording_->rig().cameras[static_cast<std::size_t>(camera_index_)];
  CameraConfig c;
  c.format = PixelFormat::kMono8;
  c.width = m.width;
  c.height = m.height;
  c.exposure_us = 0;
  c.gain = -1.0;
  c.frame_rate_hz = 0.0;
  return c;
}

Expected<void> ReplayCamera::configure(const CameraConfig& want) {
  if (auto r = check_not_streaming(); !r) return r;
  const CameraModel& m = recording_->rig().cameras[static_cast<std::size_t>(camera_index_)];
  if (want.width != m.width || want.height != m.height) {
    return make_error(name_, "size",
                      "the recording's images are " + std::to_string(m.width) + "x" +
                          std::to_string(m.height) + ", configured " + std::to_string(want.width) +
                          "x" + std::to_string(want.height));
  }
  if (auto r = check_buffer_count(want.buffer_count, kMaxReplayBuffers); !r) return r;
  config_ = want;
  notice_.clear();
  if (want.exposure_us > 0 || want.gain >= 0.0 || want.frame_rate_hz > 0.0) {
    notice_ = name_ + ": exposure, gain and frame rate are the recording's";
    config_.exposure_us = 0;
    config_.gain = -1.0;
    config_.frame_rate_hz = 0.0;
  }
  if (want.trigger == TriggerMode::kExternal) {
    config_.trigger = TriggerMode::kFreeRun;
    notice_ += (notice_.empty() ? "" : "; ") + name_ +
               ": trigger: no external trigger in a replay: free-runs";
  }
  state_ = CameraState::kConfigured;
  return {};
}

Expected<void> ReplayCamera::start() {
  if (auto r = check_configured(); !r) return r;
  ahead_.reset();  // a restart replays from the first frame
  auto ahead =
      ReplayReadAhead::start(recording_, camera_index_, config_.buffer_count, config_.format,
                             "mocap-replay" + std::to_string(camera_index_));
  if (!ahead) return make_error(name_, "start", ahead.error().message);
  ahead_ = std::move(*ahead);
  held_.assign(static_cast<std::size_t>(config_.buffer_count), false);
  next_ = 0;
  skipped_ = 0;
  triggered_ = released_ = 0;
  reset_sequence();
  start_ns_ = monotonic_ns();
  state_ = CameraState::kStreaming;
  return {};
}

void ReplayCamera::stop() noexcept {
  if (state_ == CameraState::kStreaming) state_ = CameraState::kConfigured;
}

ReplayCamera::~ReplayCamera() = default;

CameraStatus ReplayCamera::trigger() noexcept {
  if (state_ != CameraState::kStreaming) return CameraStatus::kNotStreaming;
  if (config_.trigger != TriggerMode::kSoftware) return CameraStatus::kUnsupported;
  trigger_ns_[triggered_ % kTriggerTimes] = monotonic_ns();
  ++triggered_;
  return CameraStatus::kOk;
}

CameraStatus ReplayCamera::seek(std::size_t index) noexcept {
  if (state_ != CameraState::kStreaming) return CameraStatus::kNotStreaming;
  if (index < next_) return CameraStatus::kUnsupported;  // earlier frames: restart it
  const std::size_t to = std::min(index, recording_->frames().size());
  if (to == next_) return CameraStatus::kOk;
  skipped_ += to - next_;
  next_ = to;
  ahead_->skip_to(static_cast<std::uint32_t>(to));
  reset_sequence();  // a jump on purpose: not frames the camera dropped
  return CameraStatus::kOk;
}

CameraStatus ReplayCamera::dequeue(Frame& out, int timeout_ms) noexcept {
  if (state_ != CameraState::kStreaming) return CameraStatus::kNotStreaming;
  const std::vector<FrameEntry>& frames = recording_->frames();
  if (next_ >= frames.size()) return CameraStatus::kEndOfStream;
  const std::int64_t now = monotonic_ns();
  const std::int64_t timeout_ns = static_cast<std::int64_t>(timeout_ms) * 1'000'000;
  if (config_.trigger == TriggerMode::kSoftware) {
    if (triggered_ == released_) {  // nothing can arrive while this thread waits
      if (timeout_ms > 0) sleep_until_ns(now + timeout_ns);
      counters_.timeouts.add();
      return CameraStatus::kTimeout;
    }
  } else if (pacing_ == ReplayPacing::kRecordedTiming) {
    const std::int64_t due = start_ns_ + (frames[next_].timestamp_ns - frames.front().timestamp_ns);
    if (due - now > timeout_ns) {
      if (timeout_ms > 0) sleep_until_ns(now + timeout_ns);
      counters_.timeouts.add();
      return CameraStatus::kTimeout;
    }
    if (due > now) sleep_until_ns(due);
  }
  std::size_t held = 0;
  for (const bool h : held_) held += h ? 1 : 0;
  if (held == held_.size()) {
    counters_.no_buffer.add();
    return CameraStatus::kNoBuffer;
  }
  // The frame is loaded ahead (replay_read_ahead.h); a loader behind the replay is
  // waited for within the timeout.
  ReplayReadAhead::Loaded loaded;
  const std::int64_t deadline = monotonic_ns() + (timeout_ms > 0 ? timeout_ns : 0);
  for (;;) {
    if (!ahead_->wait_next(loaded, deadline)) {
      counters_.timeouts.add();
      return CameraStatus::kTimeout;
    }
    if (loaded.frame_index >= next_) break;
    ahead_->give_back(loaded.buffer);  // loaded before a seek() passed it
  }
  const FrameEntry& entry = frames[loaded.frame_index];  // == next_: loaded in order
  next_ = loaded.frame_index + 1;
  // Where the latencies start: the trigger that released the frame (a live camera's
  // exposure starts there too), else the delivery.
  std::int64_t origin_ns = 0;
  if (config_.trigger == TriggerMode::kSoftware) {
    const std::uint64_t t = released_++;
    if (triggered_ - t <= kTriggerTimes) origin_ns = trigger_ns_[t % kTriggerTimes];
  }
  bool missing = true;
  if (loaded.status == ReplayReadAhead::Status::kError) {
    counters_.errors.add();  // malformed or wrong format: delivered as missing
  } else if (loaded.status == ReplayReadAhead::Status::kMissing) {
    counters_.missing.add();
  } else {
    missing = false;
  }
  const std::uint32_t b = loaded.buffer;
  const auto sequence = static_cast<std::uint64_t>(entry.frame);
  note_sequence(sequence);
  held_[b] = true;
  out.image = missing ? ImageView{} : ahead_->image(b).view();
  out.sequence = sequence;
  out.timestamp_ns = entry.timestamp_ns;  // the data's time: the recording's
  out.received_ns = monotonic_ns();
  out.delivered_ns = origin_ns != 0 ? origin_ns : out.received_ns;  // hal/camera.h, Frame
  out.buffer_index = b;
  out.missing = missing;
  counters_.frames.add();
  return CameraStatus::kOk;
}

CameraStatus ReplayCamera::release(const Frame& frame) noexcept {
  if (state_ != CameraState::kStreaming) return CameraStatus::kNotStreaming;
  if (frame.buffer_index >= held_.size() || !held_[frame.buffer_index]) {
    counters_.errors.add();
    return CameraStatus::kInvalidBuffer;
  }
  held_[frame.buffer_index] = false;
  ahead_->give_back(frame.buffer_index);
  return CameraStatus::kOk;
}

}  // namespace mocap::hal
