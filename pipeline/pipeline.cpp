// Design: see pipeline.h. This file is the setup and lifecycle: create() validates the
// options, start() allocates every ring and slot and starts the cameras and the five
// threads, stop() joins them and returns every buffer; retire()/finished() keep the
// count of sequences the pipeline is done with. Setup may allocate and fails with
// one-line errors. The threads' settings come from the stage table (resolve_stage(): the
// detect rule per camera) and are fixed at create(). The stage loops (the hot path) are in
// capture_stage.cpp and processing_stages.cpp, the reports (health(), stats()) in
// pipeline_stats.cpp.
#include "pipeline/pipeline.h"

#include <unistd.h>

#include <algorithm>
#include <utility>

namespace mocap::pipeline {

Expected<std::unique_ptr<Pipeline>> Pipeline::create(FrameProcessor processor,
                                                     std::vector<hal::Camera*> cameras,
                                                     std::vector<publish::OutputSink*> sinks,
                                                     const PipelineOptions& options) {
  const int n = static_cast<int>(cameras.size());
  if (n < kMinCameras || n > kMaxCameras) {
    return make_error("pipeline", "cameras",
                      std::to_string(n) + " cameras, expected " + std::to_string(kMinCameras) +
                          ".." + std::to_string(kMaxCameras));
  }
  if (n != processor.camera_count()) {
    return make_error(
        "pipeline", "cameras",
        std::to_string(n) + " cameras, the rig has " + std::to_string(processor.camera_count()));
  }
  for (int c = 0; c < n; ++c) {
    if (cameras[static_cast<std::size_t>(c)] == nullptr)
      return make_error("pipeline", "cameras", "camera " + std::to_string(c) + " is missing");
  }
  for (const publish::OutputSink* s : sinks) {
    if (s == nullptr) return make_error("pipeline", "sinks", "null sink");
  }
  // Lower bound: the period 1e9 / rate must fit the int64 nanoseconds of the capture loop.
  if (!(options.trigger_rate_hz >= 0.01) || options.trigger_rate_hz > 10000.0) {
    return make_error("pipeline", "trigger_rate_hz",
                      "must be in [0.01, 10000], got " + std::to_string(options.trigger_rate_hz));
  }
  if (options.dequeue_timeout_ms < 1 || options.dequeue_timeout_ms > 1000) {
    return make_error("pipeline", "dequeue_timeout_ms", "must be in 1..1000");
  }
  if (options.pair_by == PairBy::kTimestamp &&
      (options.pair_tolerance_us < 1 || options.pair_tolerance_us > 1'000'000)) {
    return make_error("pipeline", "pair_tolerance_us",
                      "must be in 1..1000000 us, got " + std::to_string(options.pair_tolerance_us));
  }
  const long online = sysconf(_SC_NPROCESSORS_ONLN);
  const int cpus = options.cpu_count > 0 ? options.cpu_count
                                         : static_cast<int>(std::clamp<long>(online, 1, 1024));
  std::unique_ptr<Pipeline> p(
      new Pipeline(std::move(processor), std::move(cameras), std::move(sinks), options));
  std::vector<StageId> ids = {StageId::kCapture, StageId::kIdentify, StageId::kPublish};
  for (int c = 0; c < n; ++c) ids.push_back(StageId::detect(c));
  for (StageId id : ids) {
    ResolvedStage& s = p->plan_[index(id)];
    s = resolve_stage(options.stages, id, cpus);
    if (auto v = rt::validate(rt::ThreadSpec{s.name, s.cpu, s.fifo_priority}); !v)
      return make_error("pipeline", "stages: " + s.name, v.error().message);
    if (id.kind != StageKind::kCapture && (s.ring_depth < 2 || s.ring_depth > 1024)) {
      return make_error("pipeline", "stages: " + s.name + ": ring_depth",
                        "must be in 2..1024, got " + std::to_string(s.ring_depth));
    }
  }
  return p;
}

Pipeline::Pipeline(FrameProcessor processor, std::vector<hal::Camera*> cameras,
                   std::vector<publish::OutputSink*> sinks, const PipelineOptions& options)
    : processor_(std::move(processor)),
      cameras_(std::move(cameras)),
      sinks_(std::move(sinks)),
      options_(options) {}

Pipeline::~Pipeline() { stop(); }

Expected<void> Pipeline::start() {
  if (running_) return make_error("pipeline", "start", "already running");
  notes_.clear();
  const int n = camera_count();
  // Camera buffers: the detect ring, one in the detector's hand, one on its way back.
  for (int c = 0; c < n; ++c) {
    hal::Camera& cam = *cameras_[static_cast<std::size_t>(c)];
    const std::uint32_t depth = stage(StageId::detect(c)).ring_depth;
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
  for (int c = 0; c < n; ++c) {
    hal::Camera& cam = *cameras_[static_cast<std::size_t>(c)];
    const std::uint32_t depth = stage(StageId::detect(c)).ring_depth;
    to_detect_.push_back(
        std::make_unique<rt::SpscRing<hal::Frame>>(rt::next_power_of_two_at_least(depth)));
    returned_.push_back(std::make_unique<rt::SpscRing<hal::Frame>>(
        rt::next_power_of_two_at_least(static_cast<std::size_t>(cam.config().buffer_count))));
    const FrameOutput proto = processor_.make_output();
    auto pool = rt::SlotPool<BlobSlot>::create(stage(StageId::kIdentify).ring_depth + 2,
                                               [&](std::uint32_t) {
                                                 BlobSlot s;
                                                 s.blobs = proto.blobs[static_cast<std::size_t>(c)];
                                                 return s;
                                               });
    if (!pool) return pool.error();
    blob_pools_.push_back(std::make_unique<rt::SlotPool<BlobSlot>>(std::move(pool).value()));
  }
  auto msg_pool = rt::SlotPool<MsgSlot>::create(stage(StageId::kPublish).ring_depth + 2,
                                                [](std::uint32_t) { return MsgSlot{}; });
  if (!msg_pool) return msg_pool.error();
  msg_pool_ = std::make_unique<rt::SlotPool<MsgSlot>>(std::move(msg_pool).value());
  const std::int64_t tolerance =
      options_.pair_by == PairBy::kTimestamp ? options_.pair_tolerance_us * 1000 : 0;
  auto pairer = hal::FramePairer::create(
      hal::PairerConfig{tolerance, stage(StageId::kIdentify).ring_depth, n});
  if (!pairer) return pairer.error();
  pairer_ = std::make_unique<hal::FramePairer>(std::move(pairer).value());
  out_ = std::make_unique<FrameOutput>(processor_.make_output());
  counters_ = std::make_unique<Counters>();
  lat_ = std::make_unique<Latencies>();  // value-initialised: every bucket 0
  lat_->sink_work_each = std::make_unique<LatencyHistogram[]>(sinks_.size());
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
  for (int c = 0; c < n; ++c) {
    if (auto r = cameras_[static_cast<std::size_t>(c)]->start(); !r) {
      for (int started = 0; started < c; ++started)
        cameras_[static_cast<std::size_t>(started)]->stop();
      return r.error();
    }
  }
  start_ns_ = monotonic_ns();
  stop_ns_ = 0;
  for (auto& t : last_frame_ns_) t.store(0, std::memory_order_relaxed);  // no frame yet
  threads_.clear();
  // Consumers first, so that no producer ever runs ahead of a missing consumer.
  std::vector<StageId> order = {StageId::kPublish, StageId::kIdentify};
  for (int c = 0; c < n; ++c) order.push_back(StageId::detect(c));
  order.push_back(StageId::kCapture);
  for (StageId id : order) {
    const ResolvedStage& s = stage(id);
    rt::ThreadSpec spec{s.name, options_.realtime ? s.cpu : -1,
                        options_.realtime ? s.fifo_priority : 0};
    std::function<void()> body;
    switch (id.kind) {
      case StageKind::kCapture:
        body = [this] { capture_loop(); };
        break;
      case StageKind::kDetect:
        body = [this, c = id.camera] { detect_loop(c); };
        break;
      case StageKind::kIdentify:
        body = [this] { identify_loop(); };
        break;
      case StageKind::kPublish:
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
  for (int c = 0; c < camera_count(); ++c) {
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

}  // namespace mocap::pipeline
