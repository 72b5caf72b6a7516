// Design: the replay backend: one camera of a recording folder (formats/recording.h)
// played back as a Camera, either at the recording's own timing (frame i is delivered
// at start + timestamp_i - timestamp_0, CLOCK_MONOTONIC) or as fast as possible. Images
// of 8-bit recordings are mapped in place (Recording::map_frame, zero copy: the
// detector reads the page cache; the capture thread only opens and maps the file, so
// it does not hold up the detectors that share its core), 16-bit ones read into a pool
// of buffer_count Images allocated at start(); the Frame views the mapping or the
// Image until release() (which unmaps). A recording's files must not be truncated
// while it is replayed (a mapped page that vanished would fault). Frame sequence = the recording's
// frame number, timestamp_ns = its timestamp_ns (the data's capture time, published unchanged),
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
  std::vector<MappedPgm> mapped_;  // per buffer: the mapped file (8-bit)
  std::vector<Image> images_;      // per buffer: the read image (16-bit)
  std::vector<bool> held_;
  std::size_t next_ = 0;        // index into recording_->frames()
  std::uint64_t triggers_ = 0;  // software triggers not yet consumed
  std::int64_t start_ns_ = 0;
};

}  // namespace mocap::hal
