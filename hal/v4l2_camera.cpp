// Design: see v4l2_camera.h. Setup functions build one-line errors
// "<device>: <setting>: <problem>"; hot-path functions map errno to CameraStatus and
// count it (EAGAIN/EINTR -> kAgain, ENODEV -> kDeviceLost + state kError, anything
// else -> kIoError).
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

std::uint32_t fourcc_of(PixelFormat f) noexcept {
  return f == PixelFormat::kMono8 ? V4L2_PIX_FMT_GREY : V4L2_PIX_FMT_Y16;
}

std::string fourcc_name(std::uint32_t fourcc) {
  if (fourcc == V4L2_PIX_FMT_GREY) return "GREY";
  if (fourcc == V4L2_PIX_FMT_Y16) return "Y16";
  std::string s;
  for (int i = 0; i < 4; ++i) {
    const char c = static_cast<char>((fourcc >> (8 * i)) & 0xffu);
    s += std::isprint(static_cast<unsigned char>(c)) ? c : '?';
  }
  return s;
}

std::string size_text(std::uint32_t w, std::uint32_t h) {
  return std::to_string(w) + "x" + std::to_string(h);
}

// Lower case, '_' and '-' as spaces: "Trigger_Mode" -> "trigger mode".
std::string normalised(const char* name, std::size_t max_len) {
  std::string s(name, strnlen(name, max_len));
  for (char& c : s) {
    c = (c == '_' || c == '-') ? ' '
                               : static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  }
  return s;
}

bool contains(const std::string& s, const char* word) { return s.find(word) != std::string::npos; }

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

Expected<V4l2Camera::Control> V4l2Camera::query_control(std::uint32_t id, const char* label) {
  v4l2_queryctrl qc{};
  qc.id = id;
  Control c;
  if (xioctl(VIDIOC_QUERYCTRL, &qc) < 0) {
    if (errno == EINVAL) return c;  // the device has no such control
    return sys_error(std::string("VIDIOC_QUERYCTRL ") + label, errno);
  }
  if (qc.flags & V4L2_CTRL_FLAG_DISABLED) return c;
  c.present = true;
  c.id = qc.id;
  c.type = qc.type;
  c.minimum = qc.minimum;
  c.maximum = qc.maximum;
  c.step = qc.step > 0 ? qc.step : 1;
  return c;
}

Expected<void> V4l2Camera::set_control(const Control& c, std::int32_t value, const char* key,
                                       std::int32_t& achieved) {
  v4l2_control ctrl{};
  ctrl.id = c.id;
  ctrl.value = value;
  if (xioctl(VIDIOC_S_CTRL, &ctrl) < 0)
    return sys_error(std::string(key) + ": VIDIOC_S_CTRL", errno);
  ctrl.value = 0;
  if (xioctl(VIDIOC_G_CTRL, &ctrl) < 0)
    return sys_error(std::string(key) + ": VIDIOC_G_CTRL", errno);
  achieved = ctrl.value;
  return {};
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

Expected<void> V4l2Camera::configure_format(const CameraConfig& want) {
  v4l2_format fmt{};
  fmt.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
  fmt.fmt.pix.width = static_cast<std::uint32_t>(want.width);
  fmt.fmt.pix.height = static_cast<std::uint32_t>(want.height);
  fmt.fmt.pix.pixelformat = fourcc_of(want.format);
  fmt.fmt.pix.field = V4L2_FIELD_NONE;
  if (xioctl(VIDIOC_S_FMT, &fmt) < 0) return sys_error("format: VIDIOC_S_FMT", errno);
  v4l2_format got{};
  got.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
  if (xioctl(VIDIOC_G_FMT, &got) < 0) return sys_error("format: VIDIOC_G_FMT", errno);
  // (S_FMT wrote the driver's adjusted format back into `fmt`: compare with `want`.)
  const v4l2_pix_format& p = got.fmt.pix;
  const std::uint32_t want_fourcc = fourcc_of(want.format);
  const auto want_w = static_cast<std::uint32_t>(want.width),
             want_h = static_cast<std::uint32_t>(want.height);
  if (p.pixelformat != want_fourcc || p.width != want_w || p.height != want_h) {
    return make_error(name_, "format",
                      "driver offers " + size_text(p.width, p.height) + " " +
                          fourcc_name(p.pixelformat) + " for the requested " +
                          size_text(want_w, want_h) + " " + fourcc_name(want_fourcc));
  }
  const std::uint32_t row_bytes =
      p.width * static_cast<std::uint32_t>(bytes_per_pixel(want.format));
  const std::uint32_t stride = p.bytesperline == 0 ? row_bytes : p.bytesperline;
  if (stride < row_bytes) {
    return make_error(name_, "format",
                      "bytesperline " + std::to_string(stride) + " < width * bytes per pixel " +
                          std::to_string(row_bytes));
  }
  stride_bytes_ = static_cast<int>(stride);
  // The last row needs only its pixels, not its padding.
  frame_bytes_ = stride * (p.height - 1) + row_bytes;
  if (p.sizeimage != 0 && p.sizeimage < frame_bytes_) {
    return make_error(
        name_, "format",
        "sizeimage " + std::to_string(p.sizeimage) + " < " + std::to_string(frame_bytes_));
  }
  return {};
}

Expected<void> V4l2Camera::configure_rate(const CameraConfig& want) {
  if (want.frame_rate_hz <= 0.0 || want.trigger != TriggerMode::kFreeRun) return {};
  v4l2_streamparm parm{};
  parm.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
  if (xioctl(VIDIOC_G_PARM, &parm) < 0 || !(parm.parm.capture.capability & V4L2_CAP_TIMEPERFRAME)) {
    notice_ += (notice_.empty() ? "" : "; ") +
               std::string("frame rate: no V4L2_CAP_TIMEPERFRAME: device default");
    config_.frame_rate_hz = 0.0;
    return {};
  }
  parm.parm.capture.timeperframe.numerator = 1000;
  parm.parm.capture.timeperframe.denominator =
      static_cast<std::uint32_t>(std::lround(want.frame_rate_hz * 1000.0));
  if (xioctl(VIDIOC_S_PARM, &parm) < 0) return sys_error("frame_rate_hz: VIDIOC_S_PARM", errno);
  const v4l2_fract& tpf = parm.parm.capture.timeperframe;
  config_.frame_rate_hz =
      tpf.numerator == 0 ? 0.0 : static_cast<double>(tpf.denominator) / tpf.numerator;
  return {};
}

Expected<void> V4l2Camera::configure_exposure_gain(const CameraConfig& want) {
  std::int32_t achieved = 0;
  if (want.exposure_us > 0) {
    auto mode = query_control(V4L2_CID_EXPOSURE_AUTO, "exposure auto");
    if (!mode) return mode.error();
    if (mode->present) {
      if (auto r = set_control(*mode, V4L2_EXPOSURE_MANUAL, "exposure auto", achieved); !r)
        return r;
    }
    auto exposure = query_control(V4L2_CID_EXPOSURE_ABSOLUTE, "exposure");
    if (!exposure) return exposure.error();
    if (!exposure->present)
      return make_error(name_, "exposure_us",
                        "the device has no V4L2_CID_EXPOSURE_ABSOLUTE control");
    const long units = std::lround(want.exposure_us / 100.0);  // V4L2: 100 us units
    if (units < exposure->minimum || units > exposure->maximum) {
      return make_error(name_, "exposure_us",
                        std::to_string(want.exposure_us) + " outside the device's range " +
                            std::to_string(exposure->minimum * 100) + ".." +
                            std::to_string(static_cast<long>(exposure->maximum) * 100) + " us");
    }
    if (auto r = set_control(*exposure, static_cast<std::int32_t>(units), "exposure_us", achieved);
        !r)
      return r;
    config_.exposure_us = achieved * 100;
  }
  if (want.gain >= 0.0) {
    auto gain = query_control(V4L2_CID_GAIN, "gain");
    if (!gain) return gain.error();
    if (!gain->present) return make_error(name_, "gain", "the device has no V4L2_CID_GAIN control");
    const long value = std::lround(want.gain);
    if (value < gain->minimum || value > gain->maximum) {
      return make_error(name_, "gain",
                        std::to_string(value) + " outside the device's range " +
                            std::to_string(gain->minimum) + ".." + std::to_string(gain->maximum));
    }
    if (auto r = set_control(*gain, static_cast<std::int32_t>(value), "gain", achieved); !r)
      return r;
    config_.gain = achieved;
  }
  return {};
}

Expected<void> V4l2Camera::configure_trigger(const CameraConfig& want) {
  trigger_button_ = Control{};
  if (want.trigger == TriggerMode::kFreeRun) return {};
  // Enumerate every control: trigger controls are driver-private, found by name.
  Control mode;
  std::int32_t mode_value = 1;
  v4l2_queryctrl qc{};
  qc.id = V4L2_CTRL_FLAG_NEXT_CTRL;
  while (xioctl(VIDIOC_QUERYCTRL, &qc) == 0) {
    const std::string name = normalised(reinterpret_cast<const char*>(qc.name), sizeof qc.name);
    const bool enabled = !(qc.flags & V4L2_CTRL_FLAG_DISABLED);
    if (enabled && contains(name, "trigger")) {
      if (qc.type == V4L2_CTRL_TYPE_BUTTON && contains(name, "soft")) {
        trigger_button_ = Control{true, qc.id, qc.type, qc.minimum, qc.maximum, 1};
      } else if (!mode.present && (contains(name, "mode") || contains(name, "enable")) &&
                 (qc.type == V4L2_CTRL_TYPE_BOOLEAN || qc.type == V4L2_CTRL_TYPE_INTEGER)) {
        mode = Control{true, qc.id, qc.type, qc.minimum, qc.maximum, 1};
        mode_value = std::clamp<std::int32_t>(1, qc.minimum, qc.maximum);
      } else if (!mode.present && contains(name, "mode") && qc.type == V4L2_CTRL_TYPE_MENU) {
        // The menu item naming the wanted source ("software" or "external"/"hardware"/"on").
        for (std::int32_t i = qc.minimum; i <= qc.maximum; ++i) {
          v4l2_querymenu qm{};
          qm.id = qc.id;
          qm.index = static_cast<std::uint32_t>(i);
          if (xioctl(VIDIOC_QUERYMENU, &qm) < 0) continue;
          const std::string item =
              normalised(reinterpret_cast<const char*>(qm.name), sizeof qm.name);
          const bool fits = want.trigger == TriggerMode::kSoftware
                                ? contains(item, "soft")
                                : (contains(item, "ext") || contains(item, "hard") || item == "on");
          if (fits) {
            mode = Control{true, qc.id, qc.type, qc.minimum, qc.maximum, 1};
            mode_value = i;
            break;
          }
        }
      }
    }
    qc.id |= V4L2_CTRL_FLAG_NEXT_CTRL;
  }
  const bool usable =
      mode.present && (want.trigger == TriggerMode::kExternal || trigger_button_.present);
  if (!usable) {
    config_.trigger = TriggerMode::kFreeRun;
    trigger_button_ = Control{};
    notice_ += (notice_.empty() ? "" : "; ") + name_ + ": trigger: no " +
               (want.trigger == TriggerMode::kSoftware ? "software-trigger" : "trigger-mode") +
               " control: camera free-runs (pair frames by timestamp)";
    return {};
  }
  std::int32_t achieved = 0;
  if (auto r = set_control(mode, mode_value, "trigger", achieved); !r) return r;
  if (achieved != mode_value)
    return make_error(name_, "trigger", "the driver did not accept trigger mode");
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
