// Design: names of the HAL's enums for messages and statistics, and the HAL clock.
#include "hal/camera.h"

#include <ctime>

namespace mocap::hal {

const char* to_string(CameraStatus s) noexcept {
  switch (s) {
    case CameraStatus::kOk:
      return "ok";
    case CameraStatus::kTimeout:
      return "timeout";
    case CameraStatus::kAgain:
      return "again";
    case CameraStatus::kCorruptFrame:
      return "corrupt frame";
    case CameraStatus::kNoBuffer:
      return "no buffer";
    case CameraStatus::kEndOfStream:
      return "end of stream";
    case CameraStatus::kNotStreaming:
      return "not streaming";
    case CameraStatus::kUnsupported:
      return "unsupported";
    case CameraStatus::kInvalidBuffer:
      return "invalid buffer";
    case CameraStatus::kIoError:
      return "I/O error";
    case CameraStatus::kDeviceLost:
      return "device lost";
  }
  return "unknown";
}

const char* to_string(CameraState s) noexcept {
  switch (s) {
    case CameraState::kClosed:
      return "closed";
    case CameraState::kConfigured:
      return "configured";
    case CameraState::kStreaming:
      return "streaming";
    case CameraState::kError:
      return "error";
  }
  return "unknown";
}

const char* to_string(TriggerMode m) noexcept {
  switch (m) {
    case TriggerMode::kFreeRun:
      return "free-run";
    case TriggerMode::kExternal:
      return "external";
    case TriggerMode::kSoftware:
      return "software";
  }
  return "unknown";
}

}  // namespace mocap::hal
