// Design: the setup half of the V4L2 backend (v4l2_camera.h): controls and the
// configuration of format, frame rate, exposure/gain and trigger, with one-line errors
// "<device>: <setting>: <problem>". Not on the hot path; the streaming half (open,
// start/stop, trigger, dequeue, release) is in v4l2_camera.cpp.
#include <linux/videodev2.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstring>

#include "hal/v4l2_camera.h"

namespace mocap::hal {
namespace {
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

}  // namespace

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

}  // namespace mocap::hal
