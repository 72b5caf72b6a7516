// Design: the libcamera backend (libcamera 0.0.3). A LibcameraSession owns the one
// CameraManager a process may have; cameras are opened by id or by index. configure()
// asks for a Raw stream in R8 (GREY) or R10/R12 (16-bit containers, "Y16"), validates
// it (a camera that offers another size/format is a one-line error naming both) and
// applies ExposureTime, AnalogueGain and FrameDurationLimits at start. start()
// allocates the buffers (FrameBufferAllocator), maps them and queues one Request per
// buffer. Completed requests arrive on libcamera's own thread: its handler only pushes
// the request index into an rt::SpscRing and signals an eventfd; dequeue() (the capture
// thread) polls the eventfd, pops the index and exposes the mapped buffer (zero copy);
// release() reuses and requeues the request. Sequence = the buffer's sequence number,
// timestamp = controls::SensorTimestamp (else the buffer's timestamp).
// libcamera has no trigger control: a hardware trigger is configured in the sensor
// driver, so kExternal is kept and explained in notice(), kSoftware falls back to
// free-run; pair the two cameras with hal::FramePairer by timestamp.
// libcamera types stay in the .cpp (pimpl), so users of mocap_hal do not need them.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "hal/camera.h"

namespace mocap::hal {

class LibcameraSession {
 public:
  // Starts the process's CameraManager (or returns the running one).
  static Expected<std::shared_ptr<LibcameraSession>> get();
  ~LibcameraSession();
  LibcameraSession(const LibcameraSession&) = delete;
  LibcameraSession& operator=(const LibcameraSession&) = delete;

  std::vector<std::string> camera_ids() const;

  struct Impl;
  Impl& impl() noexcept { return *impl_; }

 private:
  LibcameraSession();
  std::unique_ptr<Impl> impl_;
};

class LibcameraCamera final : public Camera {
 public:
  // Setup. `id` is a libcamera camera id or an index ("0", "1"). Errors:
  //   "libcamera: no camera found" when the system has none,
  //   "libcamera: camera 'X' not found (available: a, b)", or acquire failing.
  static Expected<std::unique_ptr<LibcameraCamera>> open(std::shared_ptr<LibcameraSession> session,
                                                         const std::string& id);
  ~LibcameraCamera() override;

  const std::string& name() const noexcept override;
  CameraState state() const noexcept override;
  Expected<void> configure(const CameraConfig& config) override;
  Expected<void> start() override;
  void stop() noexcept override;
  CameraStatus trigger() noexcept override;
  CameraStatus dequeue(Frame& out, int timeout_ms) noexcept override;
  CameraStatus release(const Frame& frame) noexcept override;
  const CameraConfig& config() const noexcept override;
  const std::string& notice() const noexcept override;
  const CameraCounters& counters() const noexcept override;

  struct Impl;

 private:
  explicit LibcameraCamera(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

}  // namespace mocap::hal
