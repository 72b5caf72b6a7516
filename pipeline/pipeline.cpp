// Design: see pipeline.h. Setup (create/start) allocates and may fail with one-line
// errors; the five loops below are the hot path: noexcept, allocation-free, lock-free,
// no logging (failures are rt::Counters, each with a single writer thread).
#include "pipeline/pipeline.h"

#include <algorithm>
#include <ctime>
#include <utility>

namespace mocap::pipeline {
namespace {

constexpr std::int64_t kIdleWaitNs = 10'000'000;  // stages re-check stop at least this often
constexpr std::int64_t kLockstepTimeoutNs = 1'000'000'000;

void sleep_until_ns(std::int64_t deadline_ns) noexcept {
  timespec ts{};
  ts.tv_sec = deadline_ns / 1'000'000'000;
  ts.tv_nsec = deadline_ns % 1'000'000'000;
  while (clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &ts, nullptr) != 0) {
  }
}

}  // namespace

Expected<std::unique_ptr<Pipeline>> Pipeline::create(FrameProcessor processor,
                                                     std::array<hal::Camera*, 2> cameras,
                                                     std::vector<JointsSink*> sinks,
                                                     const PipelineOptions& options) {
  for (int c = 0; c < 2; ++c) {
    if (cameras[static_cast<std::size_t>(c)] == nullptr)
      return make_error("pipeline", "cameras", "camera " + std::to_string(c) + " is missing");
  }
  for (const JointsSink* s : sinks) {
    if (s == nullptr) return make_error("pipeline", "sinks", "null sink");
  }
  if (!(options.trigger_rate_hz > 0.0) || options.trigger_rate_hz > 10000.0) {
    return make_error("pipeline", "trigger_rate_hz",
                      "must be in (0, 10000], got " + std::to_string(options.trigger_rate_hz));
  }
  if (options.dequeue_timeout_ms < 1 || options.dequeue_timeout_ms > 1000) {
    return make_error("pipeline", "dequeue_timeout_ms", "must be in 1..1000");
  }
  if (options.pair_by == PairBy::kTimestamp &&
      (options.pair_tolerance_us < 1 || options.pair_tolerance_us > 1'000'000)) {
    return make_error("pipeline", "pair_tolerance_us",
                      "must be in 1..1000000 us, got " + std::to_string(options.pair_tolerance_us));
  }
  for (const StageSpec& s : options.stages) {
    if (auto v = rt::validate(rt::ThreadSpec{s.name, s.cpu, s.fifo_priority}); !v)
      return make_error("pipeline", std::string("stages: ") + s.name, v.error().message);
  }
  for (std::size_t i = 1; i < kStageCount; ++i) {
    const StageSpec& s = options.stages[i];
    if (s.ring_depth < 2 || s.ring_depth > 1024) {
      return make_error("pipeline", std::string("stages: ") + s.name + ": ring_depth",
                        "must be in 2..1024, got " + std::to_string(s.ring_depth));
    }
  }
  return std::unique_ptr<Pipeline>(
      new Pipeline(std::move(processor), cameras, std::move(sinks), options));
}

Pipeline::Pipeline(FrameProcessor processor, std::array<hal::Camera*, 2> cameras,
                   std::vector<JointsSink*> sinks, const PipelineOptions& options)
    : processor_(std::move(processor)),
      cameras_(cameras),
      sinks_(std::move(sinks)),
      options_(options) {}

Pipeline::~Pipeline() { stop(); }

Expected<void> Pipeline::start() {
  if (running_) return make_error("pipeline", "start", "already running");
  notes_.clear();
  // Camera buffers: the detect ring, one in the detector's hand, one on its way back.
  for (int c = 0; c < 2; ++c) {
    hal::Camera& cam = *cameras_[static_cast<std::size_t>(c)];
    const std::uint32_t depth =
        options_.stages[index(StageId::kDetect0) + static_cast<std::size_t>(c)].ring_depth;
    if (cam.config().buffer_count < static_cast<int>(depth) + 2) {
      return make_error(
          cam.name(), "buffer_count",
          std::to_string(cam.config().buffer_count) +
              " buffers; the pipeline needs detect ring_depth + 2 = " + std::to_string(depth + 2));
    }
  }
  to_detect_.clear();
  returned_.clear();
  blob_pools_.clear();
  for (int c = 0; c < 2; ++c) {
    hal::Camera& cam = *cameras_[static_cast<std::size_t>(c)];
    const std::uint32_t depth =
        options_.stages[index(StageId::kDetect0) + static_cast<std::size_t>(c)].ring_depth;
    to_detect_.push_back(
        std::make_unique<rt::SpscRing<hal::Frame>>(rt::next_power_of_two_at_least(depth)));
    returned_.push_back(std::make_unique<rt::SpscRing<hal::Frame>>(
        rt::next_power_of_two_at_least(static_cast<std::size_t>(cam.config().buffer_count))));
    const FrameOutput proto = processor_.make_output();
    auto pool = rt::SlotPool<BlobSlot>::create(
        options_.stages[index(StageId::kIdentify)].ring_depth + 2, [&](std::uint32_t) {
          BlobSlot s;
          s.blobs = proto.blobs[static_cast<std::size_t>(c)];
          return s;
        });
    if (!pool) return pool.error();
    blob_pools_.push_back(std::make_unique<rt::SlotPool<BlobSlot>>(std::move(pool).value()));
  }
  auto msg_pool =
      rt::SlotPool<MsgSlot>::create(options_.stages[index(StageId::kPublish)].ring_depth + 2,
                                    [](std::uint32_t) { return MsgSlot{}; });
  if (!msg_pool) return msg_pool.error();
  msg_pool_ = std::make_unique<rt::SlotPool<MsgSlot>>(std::move(msg_pool).value());
  const std::int64_t tolerance =
      options_.pair_by == PairBy::kTimestamp ? options_.pair_tolerance_us * 1000 : 0;
  auto pairer = hal::FramePairer::create(
      hal::PairerConfig{tolerance, options_.stages[index(StageId::kIdentify)].ring_depth});
  if (!pairer) return pairer.error();
  pairer_ = std::make_unique<hal::FramePairer>(std::move(pairer).value());
  out_ = std::make_unique<FrameOutput>(processor_.make_output());
  counters_ = std::make_unique<Counters>();
  lat_ = std::make_unique<Latencies>();  // value-initialised: every bucket 0
  processor_.reset();
  stop_.store(false, std::memory_order_relaxed);  // no thread runs yet
  triggering_done_.store(false, std::memory_order_relaxed);
  published_.store(0, std::memory_order_relaxed);
  last_publish_ns_.store(0, std::memory_order_relaxed);
  retired_.store(0, std::memory_order_relaxed);
  publish_period_ns_.store(0, std::memory_order_relaxed);
  first_sequence_.store(0, std::memory_order_relaxed);

  if (options_.lock_memory) {
    if (std::string note = rt::lock_memory(); !note.empty()) notes_.push_back(note);
  }
  for (int c = 0; c < 2; ++c) {
    if (auto r = cameras_[static_cast<std::size_t>(c)]->start(); !r) {
      if (c == 1) cameras_[0]->stop();
      return r.error();
    }
  }
  start_ns_ = monotonic_ns();
  stop_ns_ = 0;
  for (auto& t : last_frame_ns_) t.store(0, std::memory_order_relaxed);  // no frame yet
  threads_.clear();
  // Consumers first, so that no producer ever runs ahead of a missing consumer.
  const StageId order[] = {StageId::kPublish, StageId::kIdentify, StageId::kDetect0,
                           StageId::kDetect1, StageId::kCapture};
  for (StageId id : order) {
    const StageSpec& s = options_.stages[index(id)];
    rt::ThreadSpec spec{s.name, options_.realtime ? s.cpu : -1,
                        options_.realtime ? s.fifo_priority : 0};
    std::function<void()> body;
    switch (id) {
      case StageId::kCapture:
        body = [this] { capture_loop(); };
        break;
      case StageId::kDetect0:
        body = [this] { detect_loop(0); };
        break;
      case StageId::kDetect1:
        body = [this] { detect_loop(1); };
        break;
      case StageId::kIdentify:
        body = [this] { identify_loop(); };
        break;
      case StageId::kPublish:
        body = [this] { publish_loop(); };
        break;
    }
    auto t = rt::start_thread(spec, std::move(body));
    if (!t) {
      running_ = true;
      stop();
      return t.error();
    }
    if (!t->setup().note.empty()) notes_.push_back(t->setup().note);
    threads_.push_back(std::move(t).value());
  }
  running_ = true;
  return {};
}

void Pipeline::stop() noexcept {
  if (!running_) return;
  // release: the stage threads' acquire loads see everything before the stop request.
  stop_.store(true, std::memory_order_release);
  for (Doorbell& b : bells_) b.ring();
  // Producers first: capture, then detectors, then identify, then publish.
  for (auto it = threads_.rbegin(); it != threads_.rend(); ++it) {
    if (it->joinable()) it->join();
  }
  threads_.clear();
  stop_ns_ = monotonic_ns();
  drain_after_join();
  for (hal::Camera* cam : cameras_) cam->stop();
  running_ = false;
}

void Pipeline::drain_after_join() noexcept {
  // Every thread is joined: this thread now owns every ring end.
  for (int c = 0; c < 2; ++c) {
    hal::Frame f;
    while (to_detect_[static_cast<std::size_t>(c)]->try_pop(f))
      cameras_[static_cast<std::size_t>(c)]->release(f);
  }
  release_returned();
  pairer_->flush([&](int c, const hal::PairEntry& e) {
    blob_pools_[static_cast<std::size_t>(c)]->release(e.handle);
  });
  for (auto& pool : blob_pools_) {
    rt::SlotHandle h;
    while (pool->pop(h)) pool->release(h);
  }
  rt::SlotHandle h;
  while (msg_pool_->pop(h)) msg_pool_->release(h);
}

bool Pipeline::finished() const noexcept {
  // acquire: pairs with the capture thread's release store after its last trigger.
  if (!counters_ || !triggering_done_.load(std::memory_order_acquire)) return false;
  return retired_.load(std::memory_order_acquire) >= counters_->triggered.get() || stopping();
}

void Pipeline::retire(std::uint64_t sequence) noexcept {
  // acq_rel CAS loop (two writers: identify and publish): the capture thread's acquire
  // load in lockstep sees a value only ever growing.
  std::uint64_t cur = retired_.load(std::memory_order_relaxed);
  while (cur < sequence + 1 &&
         !retired_.compare_exchange_weak(cur, sequence + 1, std::memory_order_acq_rel,
                                         std::memory_order_relaxed)) {
  }
  bells_[index(StageId::kCapture)].ring();
}

void Pipeline::release_returned() noexcept {
  for (int c = 0; c < 2; ++c) {
    hal::Frame f;
    while (returned_[static_cast<std::size_t>(c)]->try_pop(f)) {
      if (cameras_[static_cast<std::size_t>(c)]->release(f) != hal::CameraStatus::kOk)
        counters_->release_errors.add();
    }
  }
}

void Pipeline::capture_loop() noexcept {
  if (options_.hooks) options_.hooks->on_loop_start(StageId::kCapture);
  Counters& k = *counters_;
  bool software[2];
  for (int c = 0; c < 2; ++c)
    software[c] =
        cameras_[static_cast<std::size_t>(c)]->config().trigger == hal::TriggerMode::kSoftware;
  const bool triggered_mode = software[0] || software[1];
  const auto period_ns = static_cast<std::int64_t>(1e9 / options_.trigger_rate_hz);
  std::int64_t next_trigger_ns = monotonic_ns();
  while (!stopping()) {
    release_returned();
    if (triggered_mode) {
      if (options_.max_frames != 0 && k.triggered.get() >= options_.max_frames) {
        // release: finished() (acquire) then sees every counter written before.
        triggering_done_.store(true, std::memory_order_release);
        const std::uint32_t seen = bells_[index(StageId::kCapture)].snapshot();
        bells_[index(StageId::kCapture)].wait(seen, kIdleWaitNs);
        continue;
      }
      // Both pacings: at most trigger_rate_hz (lockstep may trigger later, never earlier).
      sleep_until_ns(next_trigger_ns);
      const std::int64_t now = monotonic_ns();
      // How late this trigger fires (the capture thread was not scheduled in time, or a
      // camera call overran): invisible in the latencies, which start at the trigger.
      const auto late_us =
          static_cast<std::uint64_t>(std::max<std::int64_t>(now - next_trigger_ns, 0) / 1000);
      if (late_us > k.trigger_late_max_us.get())
        k.trigger_late_max_us.add(late_us - k.trigger_late_max_us.get());
      next_trigger_ns += period_ns;
      if (next_trigger_ns < now) {  // overran a whole period: re-phase, triggers skipped
        k.trigger_overruns.add(static_cast<std::uint64_t>((now - next_trigger_ns) / period_ns) + 1);
        next_trigger_ns = now + period_ns;
      }
      for (int c = 0; c < 2; ++c) {
        if (software[c] &&
            cameras_[static_cast<std::size_t>(c)]->trigger() != hal::CameraStatus::kOk)
          k.trigger_errors.add();
      }
      k.triggered.add();
    }
    // Wait for each camera's frame at most dequeue_timeout_ms and never past the next
    // trigger (a stalled camera must not delay the other one or the trigger), then drain
    // whatever else is ready (a camera that caught up after a stall).
    std::uint64_t last_sequence = 0;
    bool pushed = false;
    for (int c = 0; c < 2; ++c) {
      hal::Camera& cam = *cameras_[static_cast<std::size_t>(c)];
      int timeout_ms = 5;  // free-run: the two cameras are polled in turn
      if (triggered_mode) {
        const std::int64_t left_ns = next_trigger_ns - monotonic_ns();
        const std::int64_t left_ms = (left_ns + 999'999) / 1'000'000;  // round up
        timeout_ms =
            static_cast<int>(std::clamp<std::int64_t>(left_ms, 0, options_.dequeue_timeout_ms));
      }
      const int max_frames = cam.config().buffer_count;
      for (int n = 0; n < max_frames; ++n) {
        hal::Frame f;
        const hal::CameraStatus st = cam.dequeue(f, n == 0 ? timeout_ms : 0);
        if (st == hal::CameraStatus::kTimeout || st == hal::CameraStatus::kAgain) {
          if (n == 0) k.dequeue_timeouts[c].add();
          break;
        }
        if (st == hal::CameraStatus::kEndOfStream) {
          triggering_done_.store(true, std::memory_order_release);  // see above
          break;
        }
        if (st != hal::CameraStatus::kOk) {
          k.dequeue_errors.add();
          break;
        }
        on_frame_received(c, f.sequence);
        if (!triggered_mode && c == 0) k.triggered.add();
        last_sequence = f.sequence;
        if (to_detect_[static_cast<std::size_t>(c)]->try_push(f)) {
          pushed = true;
          bells_[index(StageId::kDetect0) + static_cast<std::size_t>(c)].ring();
        } else {  // the detector holds every slot (stalled): drop this frame
          k.capture_ring_full[c].add();
          if (cam.release(f) != hal::CameraStatus::kOk) k.release_errors.add();
        }
      }
    }
    if (pushed && triggered_mode && options_.pacing == TriggerPacing::kLockstep) {
      const std::int64_t deadline = monotonic_ns() + kLockstepTimeoutNs;
      // acquire: pairs with retire()'s release.
      while (!stopping() && retired_.load(std::memory_order_acquire) <= last_sequence &&
             monotonic_ns() < deadline) {
        const std::uint32_t seen = bells_[index(StageId::kCapture)].snapshot();
        if (retired_.load(std::memory_order_acquire) > last_sequence) break;
        bells_[index(StageId::kCapture)].wait(seen, kIdleWaitNs);
        release_returned();
      }
    }
  }
  if (options_.hooks) options_.hooks->on_loop_end(StageId::kCapture);
}

void Pipeline::on_frame_received(int camera, std::uint64_t sequence) noexcept {
  const auto c = static_cast<std::size_t>(camera);
  const std::int64_t now = monotonic_ns();
  // relaxed: a single writer (capture); readers only want a recent, untorn time.
  const std::int64_t last = last_frame_ns_[c].load(std::memory_order_relaxed);
  last_frame_ns_[c].store(now, std::memory_order_relaxed);
  if (last != 0) {  // between two frames (start-up, before the first frame, excluded)
    rt::Counter& max_silence = counters_->camera_max_silence_us[c];
    const auto silent_us = static_cast<std::uint64_t>(std::max<std::int64_t>(now - last, 0) / 1000);
    if (silent_us > max_silence.get()) max_silence.add(silent_us - max_silence.get());
  }
  if (first_sequence_.load(std::memory_order_relaxed) == 0) {
    // release: published before this frame enters any ring; identify reads it after
    // receiving a later frame through the rings (acquire), so it sees the value.
    first_sequence_.store(sequence + 1, std::memory_order_release);
  }
}

void Pipeline::detect_loop(int camera) noexcept {
  const StageId id = camera == 0 ? StageId::kDetect0 : StageId::kDetect1;
  if (options_.hooks) options_.hooks->on_loop_start(id);
  const auto c = static_cast<std::size_t>(camera);
  rt::SpscRing<hal::Frame>& in = *to_detect_[c];
  rt::SpscRing<hal::Frame>& back = *returned_[c];
  rt::SlotPool<BlobSlot>& pool = *blob_pools_[c];
  Doorbell& bell = bells_[index(id)];
  Counters& k = *counters_;
  while (!stopping()) {
    const std::uint32_t seen = bell.snapshot();
    hal::Frame f;
    if (!in.try_pop(f)) {
      bell.wait(seen, kIdleWaitNs);
      continue;
    }
    hal::Frame newer;
    while (in.try_pop(newer)) {  // drop-oldest: work on the freshest frame
      back.try_push(f);          // cannot fail: holds every camera buffer
      k.detect_skipped[c].add();
      f = newer;
    }
    rt::SlotHandle h;
    if (!pool.acquire(h)) {  // identify holds every slot (stalled): drop
      k.detect_no_slot[c].add();
      back.try_push(f);
      continue;
    }
    const std::int64_t t0 = monotonic_ns();
    BlobSlot& slot = pool[h];
    slot.blobs.clear();
    slot.present = !f.missing && !f.image.empty();
    if (slot.present) processor_.detect_camera(camera, f.image, slot.blobs);
    slot.sequence = f.sequence;
    slot.capture_ns = f.timestamp_ns;
    const std::int64_t capture_ns = f.timestamp_ns;  // the slot is identify's once published
    back.try_push(f);                                // the image is no longer needed
    pool.publish(h);
    bells_[index(StageId::kIdentify)].ring();
    const std::int64_t t1 = monotonic_ns();
    lat_->detect_work[c].record(t1 - t0);
    lat_->detect[c].record(t1 - capture_ns);
  }
  if (options_.hooks) options_.hooks->on_loop_end(id);
}

void Pipeline::identify_loop() noexcept {
  if (options_.hooks) options_.hooks->on_loop_start(StageId::kIdentify);
  Doorbell& bell = bells_[index(StageId::kIdentify)];
  Counters& k = *counters_;
  hal::FramePairer& pairer = *pairer_;
  FrameOutput& out = *out_;
  auto on_drop = [&](int c, const hal::PairEntry& e) {
    rt::SlotPool<BlobSlot>& pool = *blob_pools_[static_cast<std::size_t>(c)];
    const std::uint64_t sequence = pool[e.handle].sequence;
    pool.release(e.handle);
    retire(sequence);
  };
  const bool by_time = options_.pair_by == PairBy::kTimestamp;
  std::uint64_t next_sequence = 0;  // the first sequence not yet accounted for
  bool counting = false;
  bool have_pair = false;
  hal::FramePair pair{};
  // Sequences between two consecutive pairs never formed a pair (dropped by a camera, the
  // capture, a detector or the pairer): counted once each, when the next pair forms
  // (pairs form in increasing sequence order). Pairs dropped later are counted by the
  // stage that drops them (identify_skipped, identify_no_slot, publish_skipped).
  auto count_unpaired = [&](std::uint64_t sequence) {
    if (!counting) {
      // acquire: see on_frame_received(); the capture stored it before any push.
      const std::uint64_t first = first_sequence_.load(std::memory_order_acquire);
      next_sequence = first == 0 ? sequence : first - 1;
      counting = true;
    }
    if (sequence >= next_sequence) {
      k.frames_unpaired.add(sequence - next_sequence);
      next_sequence = sequence + 1;
    }
  };
  while (!stopping()) {
    const std::uint32_t seen = bell.snapshot();
    for (int c = 0; c < 2; ++c) {
      rt::SlotPool<BlobSlot>& pool = *blob_pools_[static_cast<std::size_t>(c)];
      rt::SlotHandle h;
      while (pool.pop(h)) {
        hal::FramePair p;
        const std::int64_t key =
            by_time ? pool[h].capture_ns : static_cast<std::int64_t>(pool[h].sequence);
        const hal::PairEntry e{key, h};
        if (!pairer.push(c, e, p, on_drop)) continue;
        count_unpaired((*blob_pools_[0])[p.cam[0].handle].sequence);
        if (have_pair) {  // drop-oldest: a newer pair is complete
          k.identify_skipped.add();
          on_drop(0, pair.cam[0]);
          blob_pools_[1]->release(pair.cam[1].handle);
        }
        pair = p;
        have_pair = true;
      }
    }
    if (!have_pair) {
      bell.wait(seen, kIdleWaitNs);
      continue;
    }
    have_pair = false;
    const std::int64_t t0 = monotonic_ns();
    BlobSlot* slots[2] = {&(*blob_pools_[0])[pair.cam[0].handle],
                          &(*blob_pools_[1])[pair.cam[1].handle]};
    for (std::size_t c = 0; c < 2; ++c) {
      std::swap(out.blobs[c], slots[c]->blobs);  // O(1), same capacities: no allocation
      out.camera_present[c] = slots[c]->present;
    }
    const std::uint64_t sequence = slots[0]->sequence;
    const std::int64_t capture_ns = slots[0]->capture_ns;
    blob_pools_[0]->release(pair.cam[0].handle);
    blob_pools_[1]->release(pair.cam[1].handle);
    processor_.process_blobs(capture_ns, out);
    if (options_.observer) options_.observer->observe(sequence, capture_ns, out);
    rt::SlotHandle m;
    if (msg_pool_->acquire(m)) {
      make_joints_message(sequence, capture_ns, out, (*msg_pool_)[m].msg);
      if (((*msg_pool_)[m].msg.flags & client::kFlagAllBodiesFound) == 0)
        k.frames_without_result.add();
      msg_pool_->publish(m);
      bells_[index(StageId::kPublish)].ring();
    } else {  // publish holds every slot (stalled sink)
      k.identify_no_slot.add();
      retire(sequence);
    }
    const std::int64_t t1 = monotonic_ns();
    lat_->identify_work.record(t1 - t0);
    lat_->identify.record(t1 - capture_ns);
  }
  if (options_.hooks) options_.hooks->on_loop_end(StageId::kIdentify);
}

void Pipeline::publish_loop() noexcept {
  if (options_.hooks) options_.hooks->on_loop_start(StageId::kPublish);
  Doorbell& bell = bells_[index(StageId::kPublish)];
  Counters& k = *counters_;
  rt::SlotPool<MsgSlot>& pool = *msg_pool_;
  std::uint64_t skipped_seen = 0;
  std::int64_t prev_publish_ns = 0;
  while (!stopping()) {
    const std::uint32_t seen = bell.snapshot();
    rt::SlotHandle h;
    if (!pool.pop_latest(h)) {
      bell.wait(seen, kIdleWaitNs);
      continue;
    }
    if (pool.skipped() != skipped_seen) {  // older messages replaced by this one
      k.publish_skipped.add(pool.skipped() - skipped_seen);
      skipped_seen = pool.skipped();
    }
    client::JointsMessage& msg = pool[h].msg;
    const std::int64_t t0 = monotonic_ns();
    msg.publish_ns = t0;
    for (JointsSink* s : sinks_) {
      if (!s->publish(msg)) k.sink_failures.add();
    }
    const std::int64_t t1 = monotonic_ns();
    const std::uint64_t sequence = msg.sequence;
    if (prev_publish_ns != 0) {  // publish period, exponential average over ~16 frames
      const std::int64_t ema = publish_period_ns_.load(std::memory_order_relaxed);
      const std::int64_t dt = t0 - prev_publish_ns;
      // relaxed: single writer; health() only wants a recent, untorn value.
      publish_period_ns_.store(ema == 0 ? dt : ema + (dt - ema) / 16, std::memory_order_relaxed);
    }
    prev_publish_ns = t0;
    lat_->sink_work.record(t1 - t0);
    lat_->publish.record(t0 - msg.capture_ns);
    pool.release(h);
    // relaxed, then release: a reader that sees the new count (acquire) sees this time.
    last_publish_ns_.store(t0, std::memory_order_relaxed);
    published_.fetch_add(1, std::memory_order_release);
    retire(sequence);
  }
  if (options_.hooks) options_.hooks->on_loop_end(StageId::kPublish);
}

PipelineHealth Pipeline::health() const noexcept {
  PipelineHealth h;
  if (!counters_) return h;
  const Counters& k = *counters_;
  h.frames_published = frames_published();  // acquire (see there), then the time:
  h.last_publish_ns = last_publish_ns();
  h.frames_triggered = k.triggered.get();
  h.frames_dropped = k.frames_unpaired.get() + k.identify_skipped.get() + k.identify_no_slot.get() +
                     k.publish_skipped.get();
  const std::int64_t now = monotonic_ns();
  // relaxed: independent single-writer values, each only needs to be untorn and recent.
  const std::int64_t period = publish_period_ns_.load(std::memory_order_relaxed);
  if (period > 0 && h.last_publish_ns != 0 && now - h.last_publish_ns < 1'000'000'000)
    h.fps = 1e9 / static_cast<double>(period);
  h.p99_us = lat_->publish.percentile_us(0.99);
  h.max_us = static_cast<double>(lat_->publish.max_ns()) * 1e-3;
  for (std::size_t c = 0; c < 2; ++c) {
    const std::int64_t last = last_frame_ns_[c].load(std::memory_order_relaxed);
    // Before its first frame a camera has been silent since start().
    const std::int64_t since = last != 0 ? last : start_ns_;
    h.camera_silent_ms[c] = !stopping() ? (now - since) / 1'000'000 : 0;
  }
  return h;
}

PipelineStats Pipeline::stats() const {
  PipelineStats s;
  if (!counters_) return s;
  const Counters& k = *counters_;
  const std::int64_t end = stop_ns_ != 0 ? stop_ns_ : monotonic_ns();
  s.duration_s = static_cast<double>(end - start_ns_) * 1e-9;
  const PipelineHealth h = health();
  s.triggered = k.triggered.get();
  s.published = frames_published();
  s.fps = s.duration_s > 0.0 ? static_cast<double>(s.published) / s.duration_s : 0.0;
  s.latency = {{"detect0", lat_->detect[0].stats()},
               {"detect1", lat_->detect[1].stats()},
               {"identify", lat_->identify.stats()},
               {"publish", lat_->publish.stats()},
               {"detect0_work", lat_->detect_work[0].stats()},
               {"detect1_work", lat_->detect_work[1].stats()},
               {"identify_work", lat_->identify_work.stats()},
               {"sink_work", lat_->sink_work.stats()}};
  const hal::PairerCounters& pc = pairer_->counters();
  s.counters = {
      {"triggered", k.triggered.get()},
      {"published", s.published},
      {"trigger_errors", k.trigger_errors.get()},
      {"trigger_overruns", k.trigger_overruns.get()},
      {"trigger_late_max_us", k.trigger_late_max_us.get()},
      {"dequeue_timeouts_cam0", k.dequeue_timeouts[0].get()},
      {"dequeue_timeouts_cam1", k.dequeue_timeouts[1].get()},
      {"camera_max_silence_us_cam0", k.camera_max_silence_us[0].get()},
      {"camera_max_silence_us_cam1", k.camera_max_silence_us[1].get()},
      {"dequeue_errors", k.dequeue_errors.get()},
      {"release_errors", k.release_errors.get()},
      {"capture_dropped_cam0", k.capture_ring_full[0].get()},
      {"capture_dropped_cam1", k.capture_ring_full[1].get()},
      {"camera_no_buffer_cam0", cameras_[0]->counters().no_buffer.get()},
      {"camera_no_buffer_cam1", cameras_[1]->counters().no_buffer.get()},
      {"camera_dropped_cam0", cameras_[0]->counters().dropped.get()},
      {"camera_dropped_cam1", cameras_[1]->counters().dropped.get()},
      {"detect0_skipped", k.detect_skipped[0].get()},
      {"detect1_skipped", k.detect_skipped[1].get()},
      {"detect0_no_slot", k.detect_no_slot[0].get()},
      {"detect1_no_slot", k.detect_no_slot[1].get()},
      {"pair_unmatched_cam0", pc.unmatched[0].get()},
      {"pair_unmatched_cam1", pc.unmatched[1].get()},
      {"pair_overflow_cam0", pc.overflow[0].get()},
      {"pair_overflow_cam1", pc.overflow[1].get()},
      {"frames_unpaired", k.frames_unpaired.get()},
      {"identify_skipped", k.identify_skipped.get()},
      {"identify_no_slot", k.identify_no_slot.get()},
      {"publish_skipped", k.publish_skipped.get()},
      {"sink_failures", k.sink_failures.get()},
      {"frames_dropped", h.frames_dropped},
      {"frames_without_result", k.frames_without_result.get()},
  };
  return s;
}

}  // namespace mocap::pipeline
