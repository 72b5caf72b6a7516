// Design: see v4l2_camera.h. The streaming half of the V4L2 backend: open, configure
// (the settings themselves: v4l2_configure.cpp), start/stop and the hot path. Setup
// functions build one-line errors "<device>: <setting>: <problem>"; hot-path functions
// map errno to CameraStatus and count it (EAGAIN/EINTR -> kAgain, ENODEV -> kDeviceLost
// + state kError, anything else -> kIoError).
#include "hal/v4l2_camera.h"

#include <fcntl.h>
#include <linux/videodev2.h>
#include <sys/mman.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstring>

namespace mocap::hal {
namespace {

constexpr int kMaxV4l2Buffers = 32;

// A capture buffer of the mmap streaming I/O (every buffer this backend queues).
v4l2_buffer mmap_buffer(std::uint32_t index = 0) noexcept {
  v4l2_buffer b{};
  b.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
  b.memory = V4L2_MEMORY_MMAP;
  b.index = index;
  return b;
}

}  // namespace

Expected<std::unique_ptr<V4l2Camera>> V4l2Camera::open(const std::string& path,
                                                       std::shared_ptr<V4l2Sys> sys) {
  const int fd = sys->open(path.c_str(), O_RDWR | O_NONBLOCK | O_CLOEXEC);
  if (fd < 0) return make_error(path, "", std::string("cannot open: ") + std::strerror(errno));
  std::unique_ptr<V4l2Camera> cam(new V4l2Camera(path, sys, fd));
  v4l2_capability cap{};
  if (cam->xioctl(VIDIOC_QUERYCAP, &cap) < 0) {
    return make_error(
        path, "", std::string("not a V4L2 device (VIDIOC_QUERYCAP: ") + std::strerror(errno) + ")");
  }
  const std::uint32_t caps =
      (cap.capabilities & V4L2_CAP_DEVICE_CAPS) ? cap.device_caps : cap.capabilities;
  if (!(caps & V4L2_CAP_VIDEO_CAPTURE)) {
    return make_error(path, "", "not a single-planar video capture device");
  }
  if (!(caps & V4L2_CAP_STREAMING)) return make_error(path, "", "no streaming (mmap) I/O");
  return cam;
}

V4l2Camera::V4l2Camera(std::string path, std::shared_ptr<V4l2Sys> sys, int fd)
    : CameraBase(std::move(path)), sys_(std::move(sys)), fd_(fd) {}

V4l2Camera::~V4l2Camera() {
  stop();
  if (fd_ >= 0) sys_->close(fd_);
}

int V4l2Camera::xioctl(unsigned long request, void* arg) noexcept {
  int r;
  do {
    r = sys_->ioctl(fd_, request, arg);
  } while (r < 0 && errno == EINTR);
  return r;
}

Error V4l2Camera::sys_error(const std::string& what, int err) const {
  return make_error(name_, what, std::strerror(err));
}

Expected<void> V4l2Camera::configure(const CameraConfig& want) {
  if (auto r = check_not_streaming(); !r) return r;
  if (state_ == CameraState::kError)
    return make_error(name_, "configure", "device failed: reopen it");
  if (want.width <= 0 || want.height <= 0) {
    return make_error(
        name_, "size",
        "must be positive, got " + std::to_string(want.width) + "x" + std::to_string(want.height));
  }
  if (auto r = check_buffer_count(want.buffer_count, kMaxV4l2Buffers); !r) return r;
  state_ = CameraState::kClosed;
  notice_.clear();
  config_ = want;
  if (auto r = configure_format(want); !r) return r;
  if (auto r = configure_rate(want); !r) return r;
  if (auto r = configure_exposure_gain(want); !r) return r;
  if (auto r = configure_trigger(want); !r) return r;
  state_ = CameraState::kConfigured;
  return {};
}

Expected<void> V4l2Camera::start() {
  if (auto r = check_configured(); !r) return r;
  v4l2_requestbuffers req{};
  req.count = static_cast<std::uint32_t>(config_.buffer_count);
  req.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
  req.memory = V4L2_MEMORY_MMAP;
  if (xioctl(VIDIOC_REQBUFS, &req) < 0) return sys_error("start: VIDIOC_REQBUFS", errno);
  if (req.count < 2 || req.count > kMaxV4l2Buffers) {
    return make_error(name_, "start",
                      "driver granted " + std::to_string(req.count) + " buffers (need 2.." +
                          std::to_string(kMaxV4l2Buffers) + ")");
  }
  // A failed call: undo the mapping, then the error of the call's errno.
  auto fail_start = [this](const char* what) {
    const int e = errno;
    unmap_all();
    return sys_error(what, e);
  };
  buffers_.assign(req.count, Buffer{});
  for (std::uint32_t i = 0; i < req.count; ++i) {
    v4l2_buffer b = mmap_buffer(i);
    if (xioctl(VIDIOC_QUERYBUF, &b) < 0) return fail_start("start: VIDIOC_QUERYBUF");
    if (b.length < frame_bytes_) {
      unmap_all();
      return make_error(name_, "start",
                        "buffer of " + std::to_string(b.length) + " bytes < frame of " +
                            std::to_string(frame_bytes_));
    }
    void* p = sys_->mmap(b.length, PROT_READ | PROT_WRITE, MAP_SHARED, fd_,
                         static_cast<off_t>(b.m.offset));
    if (p == MAP_FAILED) return fail_start("start: mmap");
    buffers_[i] = Buffer{p, b.length, false};
  }
  for (std::uint32_t i = 0; i < req.count; ++i) {
    v4l2_buffer b = mmap_buffer(i);
    if (xioctl(VIDIOC_QBUF, &b) < 0) return fail_start("start: VIDIOC_QBUF");
  }
  int type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
  if (xioctl(VIDIOC_STREAMON, &type) < 0) return fail_start("start: VIDIOC_STREAMON");
  reset_sequence();
  state_ = CameraState::kStreaming;
  return {};
}

void V4l2Camera::unmap_all() noexcept {
  for (Buffer& b : buffers_) {
    if (b.data != nullptr) sys_->munmap(b.data, b.length);
  }
  buffers_.clear();
  v4l2_requestbuffers req{};  // frees the driver's buffers (after munmap, as V4L2 requires)
  req.count = 0;
  req.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
  req.memory = V4L2_MEMORY_MMAP;
  xioctl(VIDIOC_REQBUFS, &req);
}

void V4l2Camera::stop() noexcept {
  if (state_ != CameraState::kStreaming && state_ != CameraState::kError) return;
  if (buffers_.empty()) return;
  int type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
  xioctl(VIDIOC_STREAMOFF, &type);  // a lost device fails here; unmapping still proceeds
  unmap_all();
  if (state_ == CameraState::kStreaming) state_ = CameraState::kConfigured;
}

CameraStatus V4l2Camera::fail(int err) noexcept {
  if (err == EAGAIN || err == EINTR) return CameraStatus::kAgain;
  counters_.errors.add();
  if (err == ENODEV || err == ENXIO) {
    state_ = CameraState::kError;
    return CameraStatus::kDeviceLost;
  }
  return CameraStatus::kIoError;
}

CameraStatus V4l2Camera::trigger() noexcept {
  if (state_ == CameraState::kError) return CameraStatus::kDeviceLost;
  if (state_ != CameraState::kStreaming) return CameraStatus::kNotStreaming;
  if (config_.trigger != TriggerMode::kSoftware || !trigger_button_.present)
    return CameraStatus::kUnsupported;
  v4l2_control ctrl{};
  ctrl.id = trigger_button_.id;
  ctrl.value = 1;
  if (xioctl(VIDIOC_S_CTRL, &ctrl) < 0) return fail(errno);
  return CameraStatus::kOk;
}

CameraStatus V4l2Camera::dequeue(Frame& out, int timeout_ms) noexcept {
  if (state_ == CameraState::kError) return CameraStatus::kDeviceLost;
  if (state_ != CameraState::kStreaming) return CameraStatus::kNotStreaming;
  pollfd pfd{fd_, POLLIN, 0};
  const int pr = sys_->poll(&pfd, 1, timeout_ms);
  if (pr == 0) {
    counters_.timeouts.add();
    return CameraStatus::kTimeout;
  }
  if (pr < 0) return fail(errno);
  // POLLERR/POLLHUP without data: DQBUF's errno says whether the device is gone.
  v4l2_buffer b = mmap_buffer();
  if (xioctl(VIDIOC_DQBUF, &b) < 0) return fail(errno);
  if (b.index >= buffers_.size()) {
    counters_.errors.add();
    return CameraStatus::kIoError;
  }
  // Sequence: the driver's 32-bit counter, extended across wrap-around.
  const std::uint64_t sequence = extend_sequence32(b.sequence);
  note_sequence(sequence);

  const bool short_frame = b.bytesused != 0 && b.bytesused < frame_bytes_;
  if ((b.flags & V4L2_BUF_FLAG_ERROR) || short_frame) {
    counters_.errors.add();
    if (xioctl(VIDIOC_QBUF, &b) < 0) return fail(errno);
    return CameraStatus::kCorruptFrame;
  }
  Buffer& buf = buffers_[b.index];
  buf.held = true;
  out.image =
      ImageView{static_cast<const std::uint8_t*>(buf.data),
                config_.width,
                config_.height,
                stride_bytes_,
                config_.format,
                static_cast<std::uint16_t>(config_.format == PixelFormat::kMono8 ? 255 : 65535)};
  out.sequence = sequence;
  out.timestamp_ns = static_cast<std::int64_t>(b.timestamp.tv_sec) * 1'000'000'000 +
                     static_cast<std::int64_t>(b.timestamp.tv_usec) * 1000;
  out.received_ns = monotonic_ns();
  out.buffer_index = b.index;
  out.missing = false;
  counters_.frames.add();
  return CameraStatus::kOk;
}

CameraStatus V4l2Camera::release(const Frame& frame) noexcept {
  if (state_ == CameraState::kError) return CameraStatus::kDeviceLost;
  if (state_ != CameraState::kStreaming) return CameraStatus::kNotStreaming;
  if (frame.buffer_index >= buffers_.size() || !buffers_[frame.buffer_index].held) {
    counters_.errors.add();
    return CameraStatus::kInvalidBuffer;
  }
  v4l2_buffer b = mmap_buffer(frame.buffer_index);
  if (xioctl(VIDIOC_QBUF, &b) < 0) return fail(errno);
  buffers_[frame.buffer_index].held = false;
  return CameraStatus::kOk;
}

}  // namespace mocap::hal
