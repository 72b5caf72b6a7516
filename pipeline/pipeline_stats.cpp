// Design: see pipeline.h. The reports of the running pipeline, composed from the stages'
// readers: health() (any thread, relaxed/acquire atomic loads only, no allocation) and
// stats() (report time: builds the named latency summaries and counters, allocates).
// Counter names are part of the `mocap run --stats` JSON (docs/pipeline.md): each stage
// reports the counters it declares, per camera for cameras 0..camera_count-1 (the names
// are those of the two-camera pipeline, with the camera index as a value).
#include <string>

#include "pipeline/pipeline.h"

namespace mocap::pipeline {

PipelineHealth Pipeline::health() const noexcept {
  PipelineHealth h;
  if (!capture_) return h;
  h.frames_published = frames_published();  // acquire (see there), then the time:
  h.last_publish_ns = last_publish_ns();
  h.frames_triggered = capture_->triggered();
  h.frames_dropped = identify_->frames_dropped() + publish_->frames_dropped();
  const std::int64_t now = monotonic_ns();
  const std::int64_t period = publish_->publish_period_ns();
  if (period > 0 && h.last_publish_ns != 0 && now - h.last_publish_ns < 1'000'000'000)
    h.fps = 1e9 / static_cast<double>(period);
  const LatencyHistogram& e2e = publish_->end_to_end();
  h.p99_us = e2e.percentile_us(0.99);
  h.max_us = static_cast<double>(e2e.max_ns()) * 1e-3;
  for (const publish::OutputSink* sink : sinks_) {  // virtual calls, relaxed loads only
    const publish::OutputCounters oc = sink->counters();
    h.output_failures += oc.failures;
    h.output_dropped += oc.dropped;
  }
  h.camera_count = camera_count();
  for (int c = 0; c < h.camera_count; ++c) {
    const auto ci = static_cast<std::size_t>(c);
    h.camera_silent_ms[ci] =
        !context_.stopping() ? capture_->camera_silent_ns(c, now) / 1'000'000 : 0;
    h.detect_overflow_frames[ci] = detect_[ci]->overflow_frames();
    h.timestamp_steps[ci] = capture_->timestamp_steps(c);
  }
  return h;
}

PipelineStats Pipeline::stats() const {
  PipelineStats s;
  if (!capture_) return s;
  const std::int64_t end = stop_ns_ != 0 ? stop_ns_ : monotonic_ns();
  s.duration_s = static_cast<double>(end - start_ns_) * 1e-9;
  s.triggered = capture_->triggered();
  s.published = frames_published();
  s.fps = s.duration_s > 0.0 ? static_cast<double>(s.published) / s.duration_s : 0.0;
  for (const auto& d : detect_)
    s.latency.emplace_back(rt::counter_name("detect#", d->camera()), d->latency().stats());
  s.latency.emplace_back("identify", identify_->latency().stats());
  s.latency.emplace_back("publish", publish_->end_to_end().stats());
  for (const auto& d : detect_)
    s.latency.emplace_back(rt::counter_name("detect#_work", d->camera()), d->work().stats());
  s.latency.emplace_back("identify_work", identify_->work().stats());
  s.latency.emplace_back("sink_work", publish_->work().stats());
  for (std::size_t i = 0; i < sinks_.size(); ++i) {  // per sink: where publish time goes
    std::string name = std::string("sink_work_") + sinks_[i]->name();
    std::size_t same = 0;  // a repeated sink name gets "_2", "_3", ...: keys stay unique
    for (std::size_t j = 0; j < i; ++j) same += std::string(sinks_[j]->name()) == sinks_[i]->name();
    if (same > 0) name += "_" + std::to_string(same + 1);
    s.latency.emplace_back(std::move(name), publish_->sink_work(i).stats());
  }
  capture_->report(s.counters);
  for (const auto& d : detect_) d->report(s.counters);
  identify_->report(s.counters);
  publish_->report(s.counters);
  s.counters.emplace_back("frames_dropped", health().frames_dropped);
  // Per output sink (the output seam):
  // output_<name>_published/failures/dropped/no_listener/not_predicted.
  for (const publish::OutputSink* sink : sinks_) {
    const publish::OutputCounters oc = sink->counters();
    const std::string prefix = std::string("output_") + sink->name() + "_";
    s.counters.emplace_back(prefix + "published", oc.published);
    s.counters.emplace_back(prefix + "failures", oc.failures);
    s.counters.emplace_back(prefix + "dropped", oc.dropped);
    s.counters.emplace_back(prefix + "no_listener", oc.no_listener);
    s.counters.emplace_back(prefix + "not_predicted", oc.not_predicted);
  }
  return s;
}

}  // namespace mocap::pipeline
