// Design: see stalling_camera.h.
#include "pipeline/service/stalling_camera.h"

namespace mocap::service {

StallingCamera::StallingCamera(std::unique_ptr<hal::Camera> inner, std::uint64_t stall_after_frames)
    : inner_(std::move(inner)), stall_after_(stall_after_frames) {}

Expected<void> StallingCamera::start() {
  delivered_ = 0;
  notice_ = inner_->notice();
  notice_ += (notice_.empty() ? "" : "; ");
  notice_ += "fault injection: stalls after " + std::to_string(stall_after_) + " frames";
  return inner_->start();
}

hal::CameraStatus StallingCamera::dequeue(hal::Frame& out, int timeout_ms) noexcept {
  if (delivered_ >= stall_after_) {
    hal::sleep_until_ns(hal::monotonic_ns() + std::int64_t{timeout_ms} * 1'000'000);
    return hal::CameraStatus::kTimeout;
  }
  const hal::CameraStatus s = inner_->dequeue(out, timeout_ms);
  if (s == hal::CameraStatus::kOk) ++delivered_;
  return s;
}

}  // namespace mocap::service
