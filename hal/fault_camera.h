// Design: fault injection through the HAL (issue 8). FaultCamera decorates any
// hal::Camera and, following a fixed schedule of FaultRules chosen at setup, turns the
// inner camera's good frames into the failures real cameras produce:
//   kIoError / kCorruptFrame : dequeue fails with that status; the frame is lost
//   kTimeout                 : dequeue waits timeout_ms and reports kTimeout; the frame
//                              is lost. A rule with count N is a camera that stops for
//                              N frames and then resumes on its own
//   kTruncatedFrame          : the frame arrives with only `value` rows (a partial frame)
//   kDuplicateSequence       : the frame carries the previous frame's sequence number
//   kSwapOrder               : this frame and the next swap sequence numbers (the
//                              numbers arrive out of order: s+1, s)
//   kTimestampJump           : `value` ns are added to the timestamp (a clock step)
//   kReplaceImage            : the image is replaced by a substitute (e.g. an image full
//                              of blobs that overflows the detector)
//   kSequenceOffset          : `value` is added to the sequence number (a free-running
//                              camera whose frame counter is its own, not the trigger's:
//                              with count kForever its numbers never match another
//                              camera's, and frames pair only by timestamp)
//   kStall                   : a camera whose cable was pulled without the driver
//                              noticing: once `first` good frames were delivered, the next
//                              `count` dequeue calls (kForever: all of them) wait timeout_ms
//                              and report kTimeout without asking the inner camera, whose
//                              frames pile up there (its own drops); then it resumes.
//                              Frames already dequeued are released normally. The
//                              configuration key fault_injection.stall_after_frames of
//                              `mocap run` / `mocap record` is such a rule on camera 0
// Rules are indexed by the inner camera's good frames (0 = the first frame dequeued
// with kOk), so a schedule is deterministic whatever the timing. Frames keep their
// inner buffer_index, so release() goes straight to the inner camera; lost frames are
// released at once (a lost frame is still counted in the index). Hot calls are noexcept and
// allocation-free, like every backend; one thread (the capture thread) drives the camera.
// counters() are the inner camera's; injected(f) counts the faults this wrapper produced.
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "hal/camera.h"

namespace mocap::hal {

enum class Fault : std::uint8_t {
  kIoError,
  kCorruptFrame,
  kTimeout,
  kTruncatedFrame,
  kDuplicateSequence,
  kSwapOrder,
  kTimestampJump,
  kReplaceImage,
  kStall,
  kSequenceOffset,
};
inline constexpr std::size_t kFaultCount = 10;
const char* to_string(Fault f) noexcept;

struct FaultRule {
  static constexpr std::uint64_t kForever = ~std::uint64_t{0};
  Fault fault = Fault::kIoError;
  std::uint64_t first = 0;  // index of the first inner good frame affected
  std::uint64_t count = 1;  // consecutive frames affected (kStall: dequeue calls)
  std::int64_t value = 0;   // kTruncatedFrame: rows kept; kTimestampJump: ns added;
                            // kSequenceOffset: added to the sequence number
};

class FaultCamera final : public Camera {
 public:
  static constexpr std::size_t kMaxRules = 16;

  // `inner` must outlive the wrapper. `substitute` (kReplaceImage) must match the
  // inner camera's configured size and format and outlive the wrapper.
  static Expected<std::unique_ptr<FaultCamera>> wrap(Camera& inner,
                                                     const std::vector<FaultRule>& rules,
                                                     const Image* substitute = nullptr);
  // The same, owning the inner camera (the wrapper takes its place in a camera list).
  static Expected<std::unique_ptr<FaultCamera>> wrap(std::unique_ptr<Camera> inner,
                                                     const std::vector<FaultRule>& rules,
                                                     const Image* substitute = nullptr);

  const std::string& name() const noexcept override { return name_; }
  CameraState state() const noexcept override { return inner_.state(); }
  Expected<void> configure(const CameraConfig& config) override;
  Expected<void> start() override;
  void stop() noexcept override;
  CameraStatus trigger() noexcept override { return inner_.trigger(); }
  std::int64_t trigger_lead_ns() const noexcept override { return inner_.trigger_lead_ns(); }
  CameraStatus trigger_at(std::int64_t at_ns) noexcept override { return inner_.trigger_at(at_ns); }
  bool delivers_blobs() const noexcept override { return inner_.delivers_blobs(); }
  CameraStatus dequeue(Frame& out, int timeout_ms) noexcept override;
  CameraStatus release(const Frame& frame) noexcept override { return inner_.release(frame); }
  const CameraConfig& config() const noexcept override { return inner_.config(); }
  const std::string& notice() const noexcept override { return inner_.notice(); }
  const CameraCounters& counters() const noexcept override { return inner_.counters(); }

  // Faults injected so far (any thread).
  std::uint64_t injected(Fault f) const noexcept {
    return injected_[static_cast<std::size_t>(f)].get();
  }
  std::uint64_t injected_total() const noexcept;
  // Inner good frames seen so far (the index the rules refer to).
  std::uint64_t frames_seen() const noexcept { return seen_.get(); }

 private:
  FaultCamera(Camera& inner, const Image* substitute) noexcept;
  // The frame rule covering inner frame `index` (the first in the list wins; kStall
  // rules excluded), or nullptr.
  const FaultRule* rule_for(std::uint64_t index) const noexcept;
  // True when a kStall rule holds the camera before inner frame `index` (and counts the call).
  bool stalled(std::uint64_t index) noexcept;
  CameraStatus apply(Frame& f, int timeout_ms) noexcept;

  std::unique_ptr<Camera> owned_;  // the inner camera when the wrapper owns it
  Camera& inner_;
  std::string name_;
  const Image* substitute_ = nullptr;
  std::array<FaultRule, kMaxRules> rules_{};
  std::size_t rule_count_ = 0;
  std::array<std::uint64_t, kMaxRules> stall_calls_{};  // kStall: calls held so far
  std::array<rt::Counter, kFaultCount> injected_{};
  rt::Counter seen_;
  bool swap_pending_ = false;  // kSwapOrder: the next frame takes the previous number
  std::uint64_t last_sequence_ = 0;
  bool has_last_ = false;
};

}  // namespace mocap::hal
