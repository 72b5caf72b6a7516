// Design: the replay backend: one camera of a recording folder (formats/recording.h)
// played back as a Camera, either at the recording's own timing (frame i is delivered
// at start + timestamp_i - timestamp_0, CLOCK_MONOTONIC) or as fast as possible. Images
// are read ahead of their delivery into a pool of buffer_count Images allocated at
// start(), by a loader thread per camera (`mocap-replay<k>`, hal/replay_read_ahead.h), as a
// camera's DMA fills its buffers: dequeue() hands out a loaded buffer without copying,
// and the Frame views it until release(). A frame that is due but not loaded yet (the
// disk behind the replay) is waited for within dequeue's timeout, then kTimeout, as a
// camera whose frame has not arrived; none is skipped. Frame sequence = the recording's frame
// number, timestamp_ns = its timestamp_ns (the data's capture time, published unchanged),
// delivered_ns = the origin of the live pipeline's latencies (hal::latency_origin_ns),
// CLOCK_MONOTONIC: software-triggered, the instant of the trigger() that released the
// frame (where a live camera's exposure starts, and where a camera node's latencies
// start: the read-ahead's and dequeue's delays count); otherwise the instant dequeue
// delivered it. A frame whose file
// is absent (or malformed, or of the wrong pixel format) is delivered with missing =
// true and an empty image, and the replay goes on; after the last frame dequeue returns
// kEndOfStream.
// Trigger modes: kFreeRun (paced as above) and kSoftware (each trigger() releases
// the next frame); kExternal falls back to kFreeRun with a notice. seek(index) makes
// frame `index` (never an earlier one) the next delivered: a camera node's `trigger:
// central` replay plays the frame the central's trigger names, so that a node restarted
// mid-run resumes in step (the frames in between are neither read nor counted as dropped).
// Exposure, gain and frame rate are the recording's (notice). State, config, notice, counters and
// the dropped-frame count from gaps in the recording's frame numbers are kept by CameraBase
// (hal/camera_base.h).
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "formats/recording.h"
#include "hal/camera_base.h"
#include "hal/replay_read_ahead.h"

namespace mocap::hal {

enum class ReplayPacing : std::uint8_t { kRecordedTiming, kAsFastAsPossible };

class ReplayCamera final : public CameraBase {
 public:
  // Setup. Both cameras of a rig can share one Recording.
  static Expected<std::unique_ptr<ReplayCamera>> open(std::shared_ptr<const Recording> recording,
                                                      int camera_index, ReplayPacing pacing);

  ~ReplayCamera() override;
  Expected<void> configure(const CameraConfig& config) override;
  Expected<void> start() override;
  void stop() noexcept override;
  CameraStatus trigger() noexcept override;
  CameraStatus dequeue(Frame& out, int timeout_ms) noexcept override;
  CameraStatus release(const Frame& frame) noexcept override;
  // Streaming: frame `index` of recording.frames() is the next one delivered (at or past
  // the end: kEndOfStream next). kOk; kUnsupported for an index below the next frame.
  CameraStatus seek(std::size_t index) noexcept;
  std::uint64_t skipped() const noexcept { return skipped_; }  // frames seek() passed over

  // The configuration matching the recording (size of the rig's camera, 8-bit).
  CameraConfig native_config() const;

 private:
  ReplayCamera(std::shared_ptr<const Recording> recording, int camera_index, ReplayPacing pacing);

  std::shared_ptr<const Recording> recording_;
  int camera_index_ = 0;
  ReplayPacing pacing_;
  std::unique_ptr<ReplayReadAhead> ahead_;  // from start(): the loaded frames
  std::vector<bool> held_;
  std::size_t next_ = 0;  // index into recording_->frames()
  // Software triggers fired and consumed (released frames), and the instants of the last
  // kTriggerTimes fired: a frame's latency origin.
  static constexpr std::size_t kTriggerTimes = 64;
  std::uint64_t triggered_ = 0, released_ = 0;
  std::array<std::int64_t, kTriggerTimes> trigger_ns_{};
  std::int64_t start_ns_ = 0;
  std::uint64_t skipped_ = 0;  // the capture thread's
};

}  // namespace mocap::hal
