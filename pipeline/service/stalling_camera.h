// Design: fault injection for diagnostics and the service tests (configuration key
// fault_injection.stall_after_frames): a Camera decorator that forwards everything to
// the wrapped camera until it has delivered N frames, then behaves like a camera whose
// cable was pulled without the driver noticing: every dequeue() waits its timeout and
// returns kTimeout (counted by the pipeline as dequeue timeouts). The pipeline keeps
// running, nothing reaches the outputs, and the service's watchdog must stop pinging.
// Frames already dequeued are still released normally. Hot calls stay noexcept and
// allocation-free; the wait is the same bounded sleep a real dequeue would block for.
#pragma once

#include <cstdint>
#include <memory>
#include <string>

#include "hal/camera.h"

namespace mocap::service {

class StallingCamera final : public hal::Camera {
 public:
  StallingCamera(std::unique_ptr<hal::Camera> inner, std::uint64_t stall_after_frames);

  const std::string& name() const noexcept override { return inner_->name(); }
  hal::CameraState state() const noexcept override { return inner_->state(); }
  Expected<void> configure(const hal::CameraConfig& config) override {
    return inner_->configure(config);
  }
  Expected<void> start() override;
  void stop() noexcept override { inner_->stop(); }
  hal::CameraStatus trigger() noexcept override { return inner_->trigger(); }
  hal::CameraStatus dequeue(hal::Frame& out, int timeout_ms) noexcept override;
  hal::CameraStatus release(const hal::Frame& frame) noexcept override {
    return inner_->release(frame);
  }
  const hal::CameraConfig& config() const noexcept override { return inner_->config(); }
  const std::string& notice() const noexcept override { return notice_; }
  const hal::CameraCounters& counters() const noexcept override { return inner_->counters(); }

 private:
  std::unique_ptr<hal::Camera> inner_;
  std::uint64_t stall_after_ = 0;
  std::uint64_t delivered_ = 0;  // capture thread only
  std::string notice_;
};

}  // namespace mocap::service
