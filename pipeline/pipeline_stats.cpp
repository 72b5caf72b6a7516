// Design: see pipeline.h. The reports of the running pipeline: health() (any thread,
// relaxed/acquire atomic loads only, no allocation) and stats() (report time: builds the
// named latency summaries and counters, allocates). Counter names are part of the
// `mocap run --stats` JSON (docs/pipeline.md): new ones are only ever appended.
#include <string>

#include "pipeline/pipeline.h"

namespace mocap::pipeline {

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
  for (const publish::OutputSink* sink : sinks_) {  // virtual calls, relaxed loads only
    const publish::OutputCounters oc = sink->counters();
    h.output_failures += oc.failures;
    h.output_dropped += oc.dropped;
  }
  h.max_us = static_cast<double>(lat_->publish.max_ns()) * 1e-3;
  for (std::size_t c = 0; c < 2; ++c) {
    const std::int64_t last = last_frame_ns_[c].load(std::memory_order_relaxed);
    // Before its first frame a camera has been silent since start().
    const std::int64_t since = last != 0 ? last : start_ns_;
    h.camera_silent_ms[c] = !stopping() ? (now - since) / 1'000'000 : 0;
    h.detect_overflow_frames[c] = k.detect_library[c].detector.get(kDetectorFramesOverflow);
    h.timestamp_steps[c] = k.timestamp_backwards[c].get() + k.timestamp_jumps[c].get();
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
  for (std::size_t i = 0; i < sinks_.size(); ++i) {  // per sink: where publish time goes
    std::string name = std::string("sink_work_") + sinks_[i]->name();
    std::size_t same = 0;  // a repeated sink name gets "_2", "_3", ...: keys stay unique
    for (std::size_t j = 0; j < i; ++j) same += std::string(sinks_[j]->name()) == sinks_[i]->name();
    if (same > 0) name += "_" + std::to_string(same + 1);
    s.latency.emplace_back(std::move(name), lat_->sink_work_each[i].stats());
  }
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
  // Appended after the original set (compatible extension of the JSON "counters").
  for (std::size_t c = 0; c < 2; ++c) {
    const std::string cam = "_cam" + std::to_string(c);
    s.counters.emplace_back("timestamp_backwards" + cam, k.timestamp_backwards[c].get());
    s.counters.emplace_back("timestamp_jumps" + cam, k.timestamp_jumps[c].get());
  }
  for (std::size_t c = 0; c < 2; ++c) {
    const std::string prefix = "detect_cam" + std::to_string(c) + "_";
    const Counters::DetectLibrary& lib = k.detect_library[c];
    s.counters.emplace_back(prefix + "blobs", lib.blobs.get());
    for (std::size_t i = 0; i < kDetectorFields.size(); ++i)
      s.counters.emplace_back(prefix + kDetectorFields[i].name, lib.detector.get(i));
  }
  const Counters::IdentifyLibrary& lib = k.identify_library;
  for (std::size_t i = 0; i < kStereoFields.size(); ++i)
    s.counters.emplace_back(std::string("stereo_") + kStereoFields[i].name, lib.stereo.get(i));
  for (std::size_t i = 0; i < kIdentifyFields.size(); ++i)
    s.counters.emplace_back(std::string("identify_") + kIdentifyFields[i].name,
                            lib.identify.get(i));
  if (processor_.has_model()) {
    for (std::size_t i = 0; i < kChainFields.size(); ++i)
      s.counters.emplace_back(std::string("chain_") + kChainFields[i].name, lib.chain.get(i));
    const auto& joints = processor_.model().joints;
    for (std::size_t j = 0; j < joints.size() && 2 * j + 1 < kCoverageFields.size(); ++j) {
      s.counters.emplace_back("coverage_" + joints[j].name + "_poses", lib.coverage.get(2 * j));
      s.counters.emplace_back("coverage_" + joints[j].name + "_chain", lib.coverage.get(2 * j + 1));
    }
  }
  // Per output sink (the output seam): output_<name>_published/failures/dropped/no_listener.
  for (const publish::OutputSink* sink : sinks_) {
    const publish::OutputCounters oc = sink->counters();
    const std::string prefix = std::string("output_") + sink->name() + "_";
    s.counters.emplace_back(prefix + "published", oc.published);
    s.counters.emplace_back(prefix + "failures", oc.failures);
    s.counters.emplace_back(prefix + "dropped", oc.dropped);
    s.counters.emplace_back(prefix + "no_listener", oc.no_listener);
  }
  return s;
}

}  // namespace mocap::pipeline
