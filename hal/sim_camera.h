// Design: the simulated backend of the Camera interface, so that the live pipeline
// runs end to end without hardware (`mocap run` with no configuration).
//   SimFrameLoop : setup only. Renders `frames` frames of the built-in scenario (the
//                  simulator's motion, every camera of the scene: 2..32) into owned
//                  Images, once. Memory: frames x cameras x width x height bytes, e.g.
//                  200 x 2 x 1032 x 776 = 320 MB (8-bit); tests use short loops.
//                  Immutable afterwards, shared.
//   SimTrigger   : the shared trigger line of the rig's cameras. trigger() stamps the
//                  next sequence number with CLOCK_MONOTONIC (one writer); cameras read
//                  the stamps lock-free from a small ring of atomics.
//   SimCamera    : one camera of the rig. Trigger modes: kSoftware (this camera's
//                  trigger() fires the shared line: the master), kExternal (slaved to
//                  the shared line, trigger() is kUnsupported), kFreeRun (frames at
//                  frame_rate_hz from start(), own sequence). Sequence s shows loop
//                  frame ping-pong(s): 0,1,..,N-1,N-2,..,1,0,.. so the motion stays
//                  continuous across the loop. Zero-copy: Frame.image views the
//                  pre-rendered Image; buffer_count bounds the frames held out
//                  (kNoBuffer beyond). trigger/dequeue/release are noexcept and
//                  allocation-free. A camera that falls more than kTriggerRing triggers
//                  behind skips ahead (counted in `dropped`).
//                  State, config, notice and counters are kept by CameraBase
//                  (hal/camera_base.h).
#pragma once

#include <array>
#include <atomic>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "core/image.h"
#include "hal/camera_base.h"
#include "sim/scene.h"
#include "sim/simulate.h"

namespace mocap::hal {

class SimFrameLoop {
 public:
  // Renders options.frames frames (>= 2) of options.motion at options.fps. Setup.
  static Expected<std::shared_ptr<const SimFrameLoop>> render(const sim::SimOptions& options);

  const sim::SimScene& scene() const noexcept { return scene_; }
  int frames() const noexcept { return static_cast<int>(states_.size()); }
  double fps() const noexcept { return fps_; }
  int cameras() const noexcept { return cameras_; }
  const Image& image(int frame, int camera) const noexcept {
    return images_[static_cast<std::size_t>(frame) * static_cast<std::size_t>(cameras_) +
                   static_cast<std::size_t>(camera)];
  }
  // The true body poses of a loop frame (ground truth for tests).
  const sim::SceneState& state(int frame) const noexcept {
    return states_[static_cast<std::size_t>(frame)];
  }
  // The loop frame shown for sequence number s (ping-pong).
  int frame_of_sequence(std::uint64_t s) const noexcept;
  std::size_t memory_bytes() const noexcept;

 private:
  SimFrameLoop() = default;
  sim::SimScene scene_;
  std::vector<sim::SceneState> states_;
  std::vector<Image> images_;  // frame-major: [frame * cameras_ + camera]
  int cameras_ = 2;
  double fps_ = 100.0;
};

class SimTrigger {
 public:
  static constexpr std::uint64_t kTriggerRing = 256;  // power of two

  explicit SimTrigger(std::shared_ptr<const SimFrameLoop> loop) : loop_(std::move(loop)) {}

  // One writer thread. Fires the next exposure; returns its sequence number.
  std::uint64_t trigger() noexcept;
  // Any thread: triggers fired so far.
  std::uint64_t count() const noexcept { return count_.load(std::memory_order_acquire); }
  // Any thread: the trigger time of sequence s; false when s has not been fired or
  // its stamp was overwritten (more than kTriggerRing triggers ago).
  bool timestamp_of(std::uint64_t s, std::int64_t& timestamp_ns) const noexcept;

  const SimFrameLoop& loop() const noexcept { return *loop_; }
  const std::shared_ptr<const SimFrameLoop>& loop_ptr() const noexcept { return loop_; }

 private:
  std::shared_ptr<const SimFrameLoop> loop_;
  std::array<std::atomic<std::int64_t>, kTriggerRing> stamps_ns_{};
  std::atomic<std::uint64_t> count_{0};
};

class SimCamera final : public CameraBase {
 public:
  static Expected<std::unique_ptr<SimCamera>> open(std::shared_ptr<SimTrigger> trigger,
                                                   int camera_index);

  Expected<void> configure(const CameraConfig& config) override;
  Expected<void> start() override;
  void stop() noexcept override;
  CameraStatus trigger() noexcept override;
  CameraStatus dequeue(Frame& out, int timeout_ms) noexcept override;
  CameraStatus release(const Frame& frame) noexcept override;

  // The scene camera's size, 8-bit, software trigger for camera 0 and external
  // (slaved) for every other camera, at the loop's frame rate.
  CameraConfig native_config() const;

 private:
  SimCamera(std::shared_ptr<SimTrigger> trigger, int camera_index);

  std::shared_ptr<SimTrigger> trigger_;
  int camera_index_ = 0;
  std::vector<std::uint8_t> held_;  // per buffer: held by the caller
  std::uint32_t held_count_ = 0;
  std::uint64_t next_ = 0;  // next sequence to deliver
  std::int64_t start_ns_ = 0;
};

}  // namespace mocap::hal
