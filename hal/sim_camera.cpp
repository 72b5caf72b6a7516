// Design: see sim_camera.h. Rendering happens once in SimFrameLoop::render (both cameras
// of each frame on two threads, sim::StereoRender); the hot calls only index the
// pre-rendered images and read the trigger stamps. Waiting (no trigger yet, or a
// free-run frame not yet due) sleeps on CLOCK_MONOTONIC with absolute deadlines in
// steps of at most 1 ms.
#include "hal/sim_camera.h"

#include <algorithm>
#include <ctime>

#include "sim/frame_writer.h"
#include "sim/motion.h"
#include "sim/render.h"

namespace mocap::hal {
namespace {

constexpr int kMaxSimBuffers = 64;

}  // namespace

Expected<std::shared_ptr<const SimFrameLoop>> SimFrameLoop::render(const sim::SimOptions& options) {
  if (options.frames < 2 || options.frames > 100000) {
    return make_error("sim camera", "frames",
                      "loop length must be in 2..100000, got " + std::to_string(options.frames));
  }
  auto scene = sim::make_scene(options);
  if (!scene) return scene.error();
  auto plan = sim::plan_motion(*scene, sim::motion_spec(options));
  if (!plan) return plan.error();

  std::shared_ptr<SimFrameLoop> loop(new SimFrameLoop());
  loop->scene_ = std::move(scene).value();
  loop->fps_ = options.fps;
  const sim::SimScene& sc = loop->scene_;
  const auto n = static_cast<std::size_t>(options.frames);
  loop->states_.reserve(n);
  const int cams = static_cast<int>(sc.rig.cameras.size());
  loop->cameras_ = cams;
  loop->images_.reserve(n * static_cast<std::size_t>(cams));
  for (std::size_t f = 0; f < n; ++f) {
    sim::SceneState st = sim::make_state(sc);
    sim::apply_config(sc, plan->configs[f], st);
    st.noise_key = sim::frame_noise_key(options.seed, static_cast<std::int64_t>(f));
    loop->states_.push_back(std::move(st));
  }
  auto render = sim::MultiRender::create(sc, options.threads);
  if (!render) return render.error();
  std::vector<Image> frame_images = sim::make_camera_images(sc);  // every camera of one frame
  for (std::size_t f = 0; f < n; ++f) {
    if (!render->render(loop->states_[f], frame_images))
      return make_error("sim camera", "render", "rendering a loop frame failed");
    for (int c = 0; c < cams; ++c) {
      loop->images_.push_back(sim::make_camera_image(sc, c));
      std::swap(loop->images_.back(), frame_images[static_cast<std::size_t>(c)]);
    }
  }
  return std::shared_ptr<const SimFrameLoop>(std::move(loop));
}

int SimFrameLoop::frame_of_sequence(std::uint64_t s) const noexcept {
  const auto n = static_cast<std::uint64_t>(frames());
  const std::uint64_t period = 2 * n - 2;  // n >= 2
  const std::uint64_t p = s % period;
  return static_cast<int>(p < n ? p : period - p);
}

std::size_t SimFrameLoop::memory_bytes() const noexcept {
  std::size_t b = 0;
  for (const Image& im : images_) b += im.size_bytes();
  return b;
}

std::uint64_t SimTrigger::trigger() noexcept {
  // relaxed: only this (the single writer) thread stores count_.
  const std::uint64_t s = count_.load(std::memory_order_relaxed);
  // relaxed: the stamp is published by the release store of count_ below.
  stamps_ns_[s & (kTriggerRing - 1)].store(monotonic_ns(), std::memory_order_relaxed);
  // release: a reader that sees count_ > s (acquire) also sees stamp s.
  count_.store(s + 1, std::memory_order_release);
  return s;
}

bool SimTrigger::timestamp_of(std::uint64_t s, std::int64_t& timestamp_ns) const noexcept {
  if (s >= count()) return false;  // count(): acquire, pairs with trigger()'s release
  // relaxed: ordered after the acquire load of count_ above.
  timestamp_ns = stamps_ns_[s & (kTriggerRing - 1)].load(std::memory_order_relaxed);
  // The writer may have lapped the ring while we read: then the stamp is not s's.
  // acquire: the stamp load above cannot be reordered after this check.
  return count_.load(std::memory_order_acquire) - s < kTriggerRing;
}

Expected<std::unique_ptr<SimCamera>> SimCamera::open(std::shared_ptr<SimTrigger> trigger,
                                                     int camera_index) {
  if (!trigger) return make_error("sim camera", "", "no trigger");
  const int cams = trigger->loop().cameras();
  if (camera_index < 0 || camera_index >= cams) {
    return make_error(
        "sim camera", "camera",
        "index " + std::to_string(camera_index) + " outside 0.." + std::to_string(cams - 1));
  }
  return std::unique_ptr<SimCamera>(new SimCamera(std::move(trigger), camera_index));
}

SimCamera::SimCamera(std::shared_ptr<SimTrigger> trigger, int camera_index)
    : trigger_(std::move(trigger)), camera_index_(camera_index) {
  name_ =
      "sim:" + trigger_->loop().scene().rig.cameras[static_cast<std::size_t>(camera_index)].name;
}

CameraConfig SimCamera::native_config() const {
  const CameraModel& m =
      trigger_->loop().scene().rig.cameras[static_cast<std::size_t>(camera_index_)];
  CameraConfig c;
  c.format = trigger_->loop().image(0, camera_index_).format();
  c.width = m.width;
  c.height = m.height;
  c.exposure_us = 0;
  c.gain = -1.0;
  c.frame_rate_hz = trigger_->loop().fps();
  c.trigger = camera_index_ == 0 ? TriggerMode::kSoftware : TriggerMode::kExternal;
  c.buffer_count = 4;
  return c;
}

Expected<void> SimCamera::configure(const CameraConfig& want) {
  if (auto r = check_not_streaming(); !r) return r;
  const Image& im = trigger_->loop().image(0, camera_index_);
  if (want.width != im.width() || want.height != im.height()) {
    return make_error(name_, "size",
                      "the simulated camera renders " + std::to_string(im.width()) + "x" +
                          std::to_string(im.height()) + ", configured " +
                          std::to_string(want.width) + "x" + std::to_string(want.height));
  }
  if (want.format != im.format()) {
    return make_error(name_, "format",
                      std::string("the simulated camera renders ") +
                          (im.format() == PixelFormat::kMono8 ? "8" : "16") + "-bit images");
  }
  if (auto r = check_buffer_count(want.buffer_count, kMaxSimBuffers); !r) return r;
  if (want.trigger == TriggerMode::kFreeRun && !(want.frame_rate_hz > 0.0)) {
    return make_error(name_, "frame_rate_hz", "free-run needs a rate > 0");
  }
  config_ = want;
  notice_.clear();
  if (want.exposure_us > 0 || want.gain >= 0.0) {
    notice_ = name_ + ": exposure and gain are the simulator's";
    config_.exposure_us = 0;
    config_.gain = -1.0;
  }
  state_ = CameraState::kConfigured;
  return {};
}

Expected<void> SimCamera::start() {
  if (auto r = check_configured(); !r) return r;
  held_.assign(static_cast<std::size_t>(config_.buffer_count), 0);
  held_count_ = 0;
  next_ = config_.trigger == TriggerMode::kFreeRun ? 0 : trigger_->count();
  start_ns_ = monotonic_ns();
  state_ = CameraState::kStreaming;
  return {};
}

void SimCamera::stop() noexcept {
  if (state_ == CameraState::kStreaming) state_ = CameraState::kConfigured;
}

CameraStatus SimCamera::trigger() noexcept {
  if (state_ != CameraState::kStreaming) return CameraStatus::kNotStreaming;
  if (config_.trigger != TriggerMode::kSoftware) return CameraStatus::kUnsupported;
  trigger_->trigger();
  return CameraStatus::kOk;
}

CameraStatus SimCamera::dequeue(Frame& out, int timeout_ms) noexcept {
  if (state_ != CameraState::kStreaming) return CameraStatus::kNotStreaming;
  const std::int64_t deadline = monotonic_ns() + static_cast<std::int64_t>(timeout_ms) * 1'000'000;
  std::int64_t timestamp_ns = 0;
  if (config_.trigger == TriggerMode::kFreeRun) {
    const double period_ns = 1e9 / config_.frame_rate_hz;
    timestamp_ns = start_ns_ + static_cast<std::int64_t>(static_cast<double>(next_) * period_ns);
    if (timestamp_ns > deadline) {
      if (timeout_ms > 0) sleep_until_ns(deadline);
      counters_.timeouts.add();
      return CameraStatus::kTimeout;
    }
    if (timestamp_ns > monotonic_ns()) sleep_until_ns(timestamp_ns);
  } else {
    for (;;) {
      const std::uint64_t fired = trigger_->count();
      if (fired - next_ > SimTrigger::kTriggerRing / 2) {  // fell far behind: skip ahead
        counters_.dropped.add(fired - 1 - next_);
        next_ = fired - 1;
      }
      if (next_ < fired && trigger_->timestamp_of(next_, timestamp_ns)) break;
      const std::int64_t now = monotonic_ns();
      if (now >= deadline) {
        counters_.timeouts.add();
        return CameraStatus::kTimeout;
      }
      sleep_until_ns(std::min(deadline, now + 1'000'000));
    }
  }
  if (held_count_ == held_.size()) {
    counters_.no_buffer.add();
    return CameraStatus::kNoBuffer;
  }
  std::size_t b = 0;
  while (held_[b] != 0) ++b;
  held_[b] = 1;
  ++held_count_;
  const int f = trigger_->loop().frame_of_sequence(next_);
  out.image = trigger_->loop().image(f, camera_index_).view();
  out.sequence = next_;
  out.timestamp_ns = timestamp_ns;
  out.received_ns = monotonic_ns();
  out.buffer_index = static_cast<std::uint32_t>(b);
  out.missing = false;
  ++next_;
  counters_.frames.add();
  return CameraStatus::kOk;
}

CameraStatus SimCamera::release(const Frame& frame) noexcept {
  if (state_ != CameraState::kStreaming) return CameraStatus::kNotStreaming;
  if (frame.buffer_index >= held_.size() || held_[frame.buffer_index] == 0) {
    counters_.errors.add();
    return CameraStatus::kInvalidBuffer;
  }
  held_[frame.buffer_index] = 0;
  --held_count_;
  return CameraStatus::kOk;
}

}  // namespace mocap::hal
