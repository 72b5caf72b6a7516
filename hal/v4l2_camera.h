// Design: the V4L2 backend. Single-planar capture devices with mmap streaming I/O:
//   open     : open(O_RDWR|O_NONBLOCK), VIDIOC_QUERYCAP (capture + streaming required)
//   configure: VIDIOC_S_FMT then VIDIOC_G_FMT (GREY or Y16, exact size: a driver that
//              offers anything else is a one-line error naming both formats),
//              VIDIOC_S_PARM (free-run frame rate), V4L2_CID_EXPOSURE_AUTO -> manual,
//              V4L2_CID_EXPOSURE_ABSOLUTE (100 us units), V4L2_CID_GAIN, and the trigger:
//              a driver-private control found by name through VIDIOC_QUERYCTRL
//              enumeration ("trigger mode"/"trigger enable"; for kSoftware also a
//              button named like "software trigger"). Without one the camera
//              free-runs and notice() says so.
//   start    : VIDIOC_REQBUFS (MMAP), VIDIOC_QUERYBUF + mmap per buffer, VIDIOC_QBUF
//              all, VIDIOC_STREAMON
//   dequeue  : poll(POLLIN, timeout) + VIDIOC_DQBUF; the Frame views the mapped
//              buffer (zero copy); the driver's 32-bit sequence is extended to 64 bits
//              and gaps are counted as dropped; buffer timestamps are CLOCK_MONOTONIC
//   release  : VIDIOC_QBUF of the frame's buffer
// ENODEV anywhere after open moves the camera to kError (device unplugged).
// name() is the device path; state, config, notice, counters and the dropped-frame
// count from sequence gaps are kept by CameraBase (hal/camera_base.h).
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "hal/camera_base.h"
#include "hal/v4l2_sys.h"

namespace mocap::hal {

class V4l2Camera final : public CameraBase {
 public:
  // Setup. Error "<path>: cannot open: No such file or directory" when absent.
  static Expected<std::unique_ptr<V4l2Camera>> open(const std::string& path,
                                                    std::shared_ptr<V4l2Sys> sys = real_v4l2_sys());
  ~V4l2Camera() override;

  Expected<void> configure(const CameraConfig& config) override;
  Expected<void> start() override;
  void stop() noexcept override;
  CameraStatus trigger() noexcept override;
  CameraStatus dequeue(Frame& out, int timeout_ms) noexcept override;
  CameraStatus release(const Frame& frame) noexcept override;

 private:
  struct Buffer {
    void* data = nullptr;
    std::size_t length = 0;
    bool held = false;  // dequeued and not yet released
  };
  struct Control {
    bool present = false;
    std::uint32_t id = 0;
    std::uint32_t type = 0;
    std::int32_t minimum = 0, maximum = 0, step = 1;
  };

  V4l2Camera(std::string path, std::shared_ptr<V4l2Sys> sys, int fd);
  int xioctl(unsigned long request, void* arg) noexcept;  // retries EINTR
  Expected<Control> query_control(std::uint32_t id, const char* label);
  Expected<void> set_control(const Control& c, std::int32_t value, const char* key,
                             std::int32_t& achieved);
  Expected<void> configure_format(const CameraConfig& want);
  Expected<void> configure_rate(const CameraConfig& want);
  Expected<void> configure_exposure_gain(const CameraConfig& want);
  Expected<void> configure_trigger(const CameraConfig& want);
  Error sys_error(const std::string& what, int err) const;
  void unmap_all() noexcept;
  CameraStatus fail(int err) noexcept;  // counts and maps an errno of a hot-path call

  std::shared_ptr<V4l2Sys> sys_;
  int fd_ = -1;
  int stride_bytes_ = 0;
  std::uint32_t frame_bytes_ = 0;
  Control trigger_button_;
  std::vector<Buffer> buffers_;
};

}  // namespace mocap::hal
