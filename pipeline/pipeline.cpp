// Design: see pipeline.h. This file is the setup and lifecycle: create() validates the
// options, start() builds the stages (every ring and slot), starts the cameras and one
// thread per stage, stop() joins them and returns every buffer. Setup may allocate and
// fails with one-line errors. The threads' settings come from the stage table
// (resolve_stage(): the detect rule per camera) and are fixed at create(). The stage
// loops (the hot path) are in the stage files, the reports (health(), stats()) in
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
  // The configuration's range (core/capture_modes.h): here for callers without one.
  if (!(options.trigger_rate_hz >= kMinTriggerRateHz &&
        options.trigger_rate_hz <= kMaxTriggerRateHz)) {
    return make_error("pipeline", "trigger_rate_hz",
                      "must be in [0.01, 10000], got " + std::to_string(options.trigger_rate_hz));
  }
  if (options.cpu_latency_us < -1 || options.cpu_latency_us > rt::kMaxCpuLatencyUs) {
    return make_error("pipeline", "cpu_latency_us",
                      "must be in -1..1000000, got " + std::to_string(options.cpu_latency_us));
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

Expected<void> Pipeline::build_stages() {
  const int n = camera_count();
  capture_.reset();
  detect_.clear();
  identify_.reset();
  publish_.reset();
  auto publish = PublishStage::create(stage(StageId::kPublish).ring_depth, context_, sinks_);
  if (!publish) return publish.error();
  publish_ = std::move(publish).value();
  auto identify = IdentifyStage::create(stage(StageId::kIdentify).ring_depth, context_, processor_,
                                        publish_->input());
  if (!identify) return identify.error();
  identify_ = std::move(identify).value();
  for (int c = 0; c < n; ++c) {
    const hal::Camera& cam = *cameras_[static_cast<std::size_t>(c)];
    auto d = DetectStage::create(c, cam, stage(StageId::detect(c)).ring_depth, context_, processor_,
                                 identify_->input(c));
    if (!d) return d.error();
    detect_.push_back(std::move(d).value());
  }
  return {};  // the capture stage is built once the cameras run (start())
}

Expected<void> Pipeline::start() {
  if (running_) return make_error("pipeline", "start", "already running");
  notes_.clear();
  if (auto built = build_stages(); !built) return built;
  processor_.reset();
  context_.reset();  // no thread runs yet
  if (options_.lock_memory) {
    if (std::string note = rt::lock_memory(); !note.empty()) notes_.push_back(note);
  }
  if (options_.cpu_latency_us >= 0) {
    if (std::string note = cpu_latency_.request(options_.cpu_latency_us); !note.empty())
      notes_.push_back(note);
  }
  const int n = camera_count();
  for (int c = 0; c < n; ++c) {
    if (auto r = cameras_[static_cast<std::size_t>(c)]->start(); !r) {
      for (int started = 0; started < c; ++started)
        cameras_[static_cast<std::size_t>(started)]->stop();
      cpu_latency_.release();
      return r.error();
    }
  }
  // The cameras' silence counts from here (the stage was built before the cameras started).
  capture_ = std::make_unique<CaptureStage>(context_, cameras_, detect_pointers(), monotonic_ns());
  start_ns_ = monotonic_ns();
  stop_ns_ = 0;
  return start_threads();
}

Expected<void> Pipeline::start_threads() {
  threads_.clear();
  // Consumers first, so that no producer ever runs ahead of a missing consumer.
  std::vector<StageId> order = {StageId::kPublish, StageId::kIdentify};
  for (int c = 0; c < camera_count(); ++c) {  // a stage that passes blobs on has no thread
    if (!detect_[static_cast<std::size_t>(c)]->passes_through())
      order.push_back(StageId::detect(c));
  }
  order.push_back(StageId::kCapture);
  for (StageId id : order) {
    const ResolvedStage& s = stage(id);
    rt::ThreadSpec spec{s.name, options_.realtime ? s.cpu : -1,
                        options_.realtime ? s.fifo_priority : 0};
    std::function<void()> body;
    switch (id.kind) {
      case StageKind::kCapture:
        body = [this] { capture_->run(); };
        break;
      case StageKind::kDetect:
        body = [d = detect_[static_cast<std::size_t>(id.camera)].get()] { d->run(); };
        break;
      case StageKind::kIdentify:
        body = [this] { identify_->run(); };
        break;
      case StageKind::kPublish:
        body = [this] { publish_->run(); };
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

std::vector<DetectStage*> Pipeline::detect_pointers() const {
  std::vector<DetectStage*> out;
  for (const auto& d : detect_) out.push_back(d.get());
  return out;
}

void Pipeline::stop() noexcept {
  if (!running_) return;
  context_.request_stop();
  // Producers first: capture, then detectors, then identify, then publish.
  for (auto it = threads_.rbegin(); it != threads_.rend(); ++it) {
    if (it->joinable()) it->join();
  }
  threads_.clear();
  stop_ns_ = monotonic_ns();
  // Every thread is joined: this thread now owns every ring end.
  capture_->drain();
  identify_->drain();
  publish_->drain();
  for (hal::Camera* cam : cameras_) cam->stop();
  cpu_latency_.release();
  running_ = false;
}

bool Pipeline::finished() const noexcept {
  if (!capture_ || !context_.capture_done()) return false;  // acquire: see there
  return context_.drained() || context_.stopping();
}

}  // namespace mocap::pipeline
