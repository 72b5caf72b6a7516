// Design: the replay backend: one camera of a recording folder (formats/recording.h)
// played back as a Camera, either at the recording's own timing (frame i is delivered
// at start + timestamp_i - timestamp_0, CLOCK_MONOTONIC) or as fast as possible. Images
// are read into a pool of buffer_count Images allocated at start(); the Frame views
// one of them until release(). Frame sequence = the recording's frame number,
// timestamp_ns = its timestamp_ns (the data's capture time, published unchanged),
// delivered_ns = the CLOCK_MONOTONIC instant dequeue delivered it (image loaded): the
// origin of the live pipeline's latencies (hal::latency_origin_ns). A frame whose file
// is absent (or malformed, or of the wrong pixel format) is delivered with missing =
// true and an empty image, and the replay goes on; after the last frame dequeue returns
// kEndOfStream.
// Trigger modes: kFreeRun (paced as above) and kSoftware (each trigger() releases
// the next frame); kExternal falls back to kFreeRun with a notice. Exposure, gain and
// frame rate are the recording's (notice).
// State, config, notice, counters and the dropped-frame count from gaps in the
// recording's frame numbers are kept by CameraBase (hal/camera_base.h).
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "formats/recording.h"
#include "hal/camera_base.h"

namespace mocap::hal {

enum class ReplayPacing : std::uint8_t { kRecordedTiming, kAsFastAsPossible };

class ReplayCamera final : public CameraBase {
 public:
  // Setup. Both cameras of a rig can share one Recording.
  static Expected<std::unique_ptr<ReplayCamera>> open(std::shared_ptr<const Recording> recording,
                                                      int camera_index, ReplayPacing pacing);

  Expected<void> configure(const CameraConfig& config) override;
  Expected<void> start() override;
  void stop() noexcept override;
  CameraStatus trigger() noexcept override;
  CameraStatus dequeue(Frame& out, int timeout_ms) noexcept override;
  CameraStatus release(const Frame& frame) noexcept override;

  // The configuration matching the recording (size of the rig's camera, 8-bit).
  CameraConfig native_config() const;

 private:
  ReplayCamera(std::shared_ptr<const Recording> recording, int camera_index, ReplayPacing pacing);

  std::shared_ptr<const Recording> recording_;
  int camera_index_ = 0;
  ReplayPacing pacing_;
  std::vector<Image> images_;
  std::vector<bool> held_;
  std::size_t next_ = 0;        // index into recording_->frames()
  std::uint64_t triggers_ = 0;  // software triggers not yet consumed
  std::int64_t start_ns_ = 0;
};

}  // namespace mocap::hal
