// Design: see replay_camera.h. Waiting uses clock_nanosleep on CLOCK_MONOTONIC with
// an absolute deadline (no drift over a long replay).
#include "hal/replay_camera.h"

#include <ctime>

namespace mocap::hal {
namespace {

constexpr int kMaxReplayBuffers = 32;

}  // namespace

Expected<std::unique_ptr<ReplayCamera>> ReplayCamera::open(
    std::shared_ptr<const Recording> recording, int camera_index, ReplayPacing pacing) {
  if (!recording) return make_error("replay", "", "no recording");
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
  const auto buffers = static_cast<std::size_t>(config_.buffer_count);
  mapped_.clear();
  mapped_.resize(buffers);
  images_.assign(buffers, Image{});
  if (config_.format != PixelFormat::kMono8) {  // 16-bit: read (swapped) into owned images
    for (Image& im : images_) im.allocate(config_.width, config_.height, config_.format, 65535);
  }
  held_.assign(buffers, false);
  next_ = 0;
  triggers_ = 0;
  reset_sequence();
  start_ns_ = monotonic_ns();
  state_ = CameraState::kStreaming;
  return {};
}

void ReplayCamera::stop() noexcept {
  if (state_ == CameraState::kStreaming) state_ = CameraState::kConfigured;
}

CameraStatus ReplayCamera::trigger() noexcept {
  if (state_ != CameraState::kStreaming) return CameraStatus::kNotStreaming;
  if (config_.trigger != TriggerMode::kSoftware) return CameraStatus::kUnsupported;
  ++triggers_;
  return CameraStatus::kOk;
}

CameraStatus ReplayCamera::dequeue(Frame& out, int timeout_ms) noexcept {
  if (state_ != CameraState::kStreaming) return CameraStatus::kNotStreaming;
  const std::vector<FrameEntry>& frames = recording_->frames();
  if (next_ >= frames.size()) return CameraStatus::kEndOfStream;
  const std::int64_t now = monotonic_ns();
  const std::int64_t timeout_ns = static_cast<std::int64_t>(timeout_ms) * 1'000'000;
  if (config_.trigger == TriggerMode::kSoftware) {
    if (triggers_ == 0) {  // nothing can arrive while this thread waits
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
  std::size_t b = 0;
  while (b < held_.size() && held_[b]) ++b;
  if (b == held_.size()) {
    counters_.no_buffer.add();
    return CameraStatus::kNoBuffer;
  }
  const FrameEntry& entry = frames[next_++];
  if (config_.trigger == TriggerMode::kSoftware) --triggers_;
  ImageView view{};
  bool missing = false;
  if (config_.format == PixelFormat::kMono8) {  // zero copy: the file mapped in place
    const Expected<PgmMapResult> map =
        recording_->map_frame(camera_index_, entry.frame, mapped_[b]);
    if (!map.ok() || *map == PgmMapResult::kNeedsCopy) {
      counters_.errors.add();  // malformed, or 16-bit: delivered as missing
      missing = true;
    } else if (*map == PgmMapResult::kMissing) {
      counters_.missing.add();
      missing = true;
    } else {
      view = mapped_[b].view();
    }
  } else {
    Image& image = images_[b];
    const Expected<FrameLoad> load = recording_->load_frame(camera_index_, entry.frame, image);
    if (!load.ok() || image.format() != config_.format) {
      counters_.errors.add();  // malformed or wrong format: delivered as missing
      missing = true;
    } else if (*load == FrameLoad::kMissing) {
      counters_.missing.add();
      missing = true;
    } else {
      view = image.view();
    }
  }
  const auto sequence = static_cast<std::uint64_t>(entry.frame);
  note_sequence(sequence);
  held_[b] = true;
  out.image = view;
  out.sequence = sequence;
  out.timestamp_ns = entry.timestamp_ns;  // the data's time: the recording's
  out.received_ns = monotonic_ns();
  out.delivered_ns = out.received_ns;  // latencies start here (hal/camera.h, Frame)
  out.buffer_index = static_cast<std::uint32_t>(b);
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
  mapped_[frame.buffer_index].reset();  // munmap: the frame's file is not looked at again
  return CameraStatus::kOk;
}

}  // namespace mocap::hal
