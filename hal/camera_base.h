// Design: the part of a Camera that every owning backend (V4L2, replay, simulated)
// keeps and reports in the same way, so each backend holds only its own capture logic:
//   - the reported state: name, CameraState, achieved CameraConfig, the configure()
//     notice and the CameraCounters, with the Camera accessors (final) over them;
//   - the setup checks of configure()/start() (state, buffer_count range);
//   - the sequence bookkeeping: gaps between consecutive frame sequence numbers are
//     counted in counters_.dropped, and a driver's 32-bit sequence can be extended to
//     64 bits across wrap-around.
// The members are protected and written by the backend (single writer: the capture
// thread, as for every Camera). The sequence helpers are noexcept and allocation-free
// (hot path); the checks are setup code. The Camera interface (hal/camera.h) is unchanged: users
// keep seeing a Camera; wrappers that forward to another camera (FaultCamera) do not derive from
// this.
#pragma once

#include <cstdint>
#include <string>
#include <utility>

#include "hal/camera.h"

namespace mocap::hal {

class CameraBase : public Camera {
 public:
  const std::string& name() const noexcept final { return name_; }
  CameraState state() const noexcept final { return state_; }
  const CameraConfig& config() const noexcept final { return config_; }
  const std::string& notice() const noexcept final { return notice_; }
  const CameraCounters& counters() const noexcept final { return counters_; }

 protected:
  CameraBase() = default;
  explicit CameraBase(std::string name) : name_(std::move(name)) {}

  // Setup checks every backend makes, as one-line errors naming the camera:
  // configure() while streaming; start() when not configured; a buffer_count outside
  // 2..max_buffers.
  Expected<void> check_not_streaming() const {
    if (state_ == CameraState::kStreaming)
      return make_error(name_, "configure", "stop streaming first");
    return {};
  }
  Expected<void> check_configured() const {
    if (state_ != CameraState::kConfigured) {
      return make_error(name_, "start",
                        std::string("camera is ") + to_string(state_) + ", not configured");
    }
    return {};
  }
  Expected<void> check_buffer_count(int buffer_count, int max_buffers) const {
    if (buffer_count < 2 || buffer_count > max_buffers) {
      return make_error(
          name_, "buffer_count",
          "must be in 2.." + std::to_string(max_buffers) + ", got " + std::to_string(buffer_count));
    }
    return {};
  }

  // Forget the last sequence (at start()): the next frame counts no gap.
  void reset_sequence() noexcept {
    have_sequence_ = false;
    last_sequence_ = 0;
  }
  // Records the sequence number of a delivered frame; a jump forward from the last one
  // counts the skipped numbers in counters_.dropped.
  void note_sequence(std::uint64_t sequence) noexcept {
    if (have_sequence_ && sequence > last_sequence_ + 1)
      counters_.dropped.add(sequence - last_sequence_ - 1);
    have_sequence_ = true;
    last_sequence_ = sequence;
  }
  // A driver's 32-bit sequence counter extended to 64 bits: the unsigned 32-bit
  // difference from the last noted sequence, added to it (correct across wrap-around
  // while fewer than 2^32 frames pass between two calls).
  std::uint64_t extend_sequence32(std::uint32_t raw) const noexcept {
    if (!have_sequence_) return raw;
    return last_sequence_ +
           static_cast<std::uint32_t>(raw - static_cast<std::uint32_t>(last_sequence_));
  }

  std::string name_;
  CameraState state_ = CameraState::kClosed;
  CameraConfig config_;
  std::string notice_;
  CameraCounters counters_;

 private:
  bool have_sequence_ = false;
  std::uint64_t last_sequence_ = 0;
};

}  // namespace mocap::hal
