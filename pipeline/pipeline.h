// Design: the live real-time pipeline over the rig's 2..kMaxCameras cameras: the wiring
// of its stage objects, each on its own thread pinned from the one stage table
// (stage_table.h), passing preallocated buffers through lock-free SPSC rings and pools.
//
//   CaptureStage --frame ring[c]--> DetectStage c --blob pool[c]--> IdentifyStage --message pool-->
//   PublishStage
//        ^                               |                        (match by sequence, (OutputSinks)
//        +-------- return ring[c] -------+                         pairs + N-view merge,
//          (camera buffer back right after detection)              identify, angles)
//
// Each stage owns its input ring or pool (sized by its stage-table ring depth), its
// counters (named where they are declared, rt/counter_group.h) and its histograms, and
// is the only writer of them; the stages share only the StageContext (stop flag,
// doorbells, the sequence ledger: stage_context.h). Pipeline keeps the wiring, start and
// stop, and composes the health view and the statistics from the stages' readers.
// Ownership: a camera buffer (Frame) belongs to the capture thread, which alone calls
// release(); a detector hands every Frame back through its return ring. Everything is
// allocated at start(); the stage loops allocate nothing, take no lock, log nothing.
// Drop policy (the capture never blocks): each consumer drains its input and works on
// the NEWEST item, returning the older ones (counted as skipped); a producer whose
// consumer has stalled long enough to hold every slot drops the incoming item (counted).
// Latency: every sample is measured from the frame's latency origin on CLOCK_MONOTONIC
// (hal::latency_origin_ns: a live camera's trigger timestamp, a replay's delivery; the
// published capture_ns stays Frame.timestamp_ns): detect done, identify done, published
// (end to end), into LatencyHistograms that any thread may read while the pipeline runs.
// Health: health(), frames_published() and last_publish_ns() may be read from any thread.
// Sources: pipeline.cpp (setup, start/stop), pipeline_stats.cpp (health, stats); the
// stages in capture_stage, detect_stage, identify_stage and publish_stage.
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "core/camera_set.h"
#include "core/expected.h"
#include "core/latency_histogram.h"
#include "hal/camera.h"
#include "pipeline/capture_stage.h"
#include "pipeline/detect_stage.h"
#include "pipeline/identify_stage.h"
#include "pipeline/pipeline_health.h"
#include "pipeline/pipeline_options.h"
#include "pipeline/publish/output_sink.h"
#include "pipeline/publish_stage.h"
#include "pipeline/stage_context.h"
#include "pipeline/stage_table.h"
#include "rt/cpu_latency.h"
#include "rt/thread.h"
#include "track/frame_processor.h"

namespace mocap::pipeline {

struct PipelineStats {
  double duration_s = 0.0;
  std::uint64_t triggered = 0;
  std::uint64_t published = 0;
  double fps = 0.0;  // published / duration
  // (name, summary): detect<k>/identify/publish are latencies from the trigger
  // ("publish" is trigger-to-publish, end to end); *_work are the stage's own times.
  std::vector<std::pair<std::string, LatencyStats>> latency;
  std::vector<std::pair<std::string, std::uint64_t>> counters;
  // Signed or fractional values (camera nodes' clock offsets); JSON "gauges", when any.
  std::vector<std::pair<std::string, double>> gauges;
};

class Pipeline final : public HealthSource {
 public:
  // `cameras` (2..kMaxCameras, in rig order: as many as the processor's rig has) are
  // configured but not started (the pipeline starts and stops them and drives them from
  // its capture thread); sinks and cameras must outlive the pipeline.
  static Expected<std::unique_ptr<Pipeline>> create(FrameProcessor processor,
                                                    std::vector<hal::Camera*> cameras,
                                                    std::vector<publish::OutputSink*> sinks,
                                                    const PipelineOptions& options);
  ~Pipeline() override;
  Pipeline(const Pipeline&) = delete;
  Pipeline& operator=(const Pipeline&) = delete;

  // Allocates every ring and slot, starts the cameras and the 3 + cameras threads. The
  // fallbacks taken (no SCHED_FIFO, no mlockall, no pinning, no CPU latency request) are
  // in notes().
  Expected<void> start();
  // Stops triggering, joins every thread (each wakes within ~20 ms), returns every
  // buffer to its camera and stops the cameras. Idempotent.
  void stop() noexcept;
  bool running() const noexcept { return running_; }
  // True once the triggering ended (max_frames triggered, or a replayed recording's end)
  // and every frame it could deliver was published or dropped.
  bool finished() const noexcept;

  const std::vector<std::string>& notes() const noexcept { return notes_; }

  // Health, any thread (see PipelineHealth) except concurrently with start(), which
  // rebuilds the counters. Zeroes before the first start().
  PipelineHealth health() const noexcept override;
  std::uint64_t frames_published() const noexcept {
    return publish_ ? publish_->published() : 0;  // acquire (see PublishStage)
  }
  std::int64_t last_publish_ns() const noexcept {
    return publish_ ? publish_->last_publish_ns() : 0;
  }

  // The owner thread (the one calling start/stop), also while running: every value is
  // read atomically, values at slightly different instants. Report time: allocates.
  PipelineStats stats() const;
  // The trigger-to-publish histogram (any thread; periodic interval reports).
  const LatencyHistogram* end_to_end() const noexcept override {
    return publish_ ? &publish_->end_to_end() : nullptr;
  }
  const FrameProcessor& processor() const noexcept { return processor_; }
  int camera_count() const noexcept { return static_cast<int>(cameras_.size()); }
  // The resolved stage of thread `id` (stage table rule and overrides applied).
  const ResolvedStage& stage(StageId id) const noexcept { return plan_[index(id)]; }

 private:
  Pipeline(FrameProcessor processor, std::vector<hal::Camera*> cameras,
           std::vector<publish::OutputSink*> sinks, const PipelineOptions& options);
  Expected<void> build_stages();
  Expected<void> start_threads();
  std::vector<DetectStage*> detect_pointers() const;

  FrameProcessor processor_;
  std::vector<hal::Camera*> cameras_;  // 2..kMaxCameras, fixed at create()
  std::vector<publish::OutputSink*> sinks_;
  PipelineOptions options_;
  std::array<ResolvedStage, kMaxStages> plan_{};  // per thread (index()), at create()
  std::vector<std::string> notes_;
  bool running_ = false;
  StageContext context_{options_};

  // Built at start(), in this order (each stage's output is its consumer's input).
  std::unique_ptr<PublishStage> publish_;
  std::unique_ptr<IdentifyStage> identify_;
  std::vector<std::unique_ptr<DetectStage>> detect_;
  std::unique_ptr<CaptureStage> capture_;
  std::vector<rt::RtThread> threads_;
  rt::CpuLatencyRequest cpu_latency_;  // held from start() to stop()
  std::int64_t start_ns_ = 0, stop_ns_ = 0;
};

}  // namespace mocap::pipeline
