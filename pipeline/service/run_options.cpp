// Design: pipeline::PipelineOptions from a validated RunConfig (live_setup.h,
// pipeline_options()): the pipeline keys, the stage table's overrides on top of
// pipeline::kDefaultStages, and the camera-node bounds after which a silent node's
// cameras no longer hold the frame sets back (pipeline_options.h, silent_after_ns).
// Setup code: allocation-free but not on the hot path.
#include <algorithm>

#include "pipeline/service/live_setup.h"

namespace mocap::service {

using config::CameraBackend;

pipeline::PipelineOptions pipeline_options(const config::RunConfig& cfg) {
  pipeline::PipelineOptions o;
  o.trigger_rate_hz = cfg.pipeline.trigger_rate_hz;
  o.pacing = cfg.pipeline.pacing;
  o.every_frame = cfg.pipeline.every_frame;
  o.catch_up_ns = static_cast<std::int64_t>(cfg.pipeline.catch_up_ms) * 1'000'000;
  o.realtime = cfg.pipeline.realtime;
  o.lock_memory = cfg.pipeline.lock_memory;
  o.cpu_latency_us = cfg.pipeline.cpu_latency_us;
  o.dequeue_timeout_ms = cfg.pipeline.dequeue_timeout_ms;
  o.pair_by = cfg.pipeline.pair_by == config::PairBy::kTimestamp ? pipeline::PairBy::kTimestamp
                                                                 : pipeline::PairBy::kSequence;
  o.pair_tolerance_us = cfg.pipeline.pair_tolerance_us;
  for (std::size_t i = 0; i < config::kStageCount; ++i) {
    const config::StageSettings& s = cfg.pipeline.stages[i];
    pipeline::StageSpec& d = o.stages.rows[i];
    if (s.cpu) d.cpu = *s.cpu;
    if (s.priority) d.fifo_priority = *s.priority;
    if (s.ring_depth) d.ring_depth = *s.ring_depth;
  }
  for (std::size_t c = 0; c < cfg.pipeline.detect_camera.size(); ++c) {  // detect<k>
    const config::StageSettings& s = cfg.pipeline.detect_camera[c];
    pipeline::DetectOverride& d = o.stages.detect[c];
    if (s.cpu) d.cpu = *s.cpu;
    if (s.priority) d.fifo_priority = *s.priority;
    if (s.ring_depth) d.ring_depth = *s.ring_depth;
  }
  // Camera nodes the central does not trigger (trigger external / free_run): a silent
  // node's cameras are waited for node.timeout_ms plus one frame period (the camera's
  // frame_rate_hz, else pipeline.trigger_rate_hz: the trigger line's rate), then the
  // sets go on without them (hal::FramePairer, "silent cameras").
  for (std::size_t c = 0; c < cfg.cameras.size() && c < o.silent_after_ns.size(); ++c) {
    const config::CameraSettings& s = cfg.cameras[c];
    if (s.backend != CameraBackend::kNode || !s.trigger ||
        *s.trigger == hal::TriggerMode::kSoftware)
      continue;
    const double rate_hz = s.frame_rate_hz ? *s.frame_rate_hz : cfg.pipeline.trigger_rate_hz;
    o.silent_after_ns[c] = static_cast<std::int64_t>(cfg.node.timeout_ms) * 1'000'000 +
                           static_cast<std::int64_t>(std::min(1e9 / rate_hz, 1e12));
  }
  return o;
}

}  // namespace mocap::service
