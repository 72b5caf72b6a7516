// Design: the live real-time pipeline over the rig's 2..kMaxCameras cameras: capture,
// one detect thread per camera, identify and publish, pinned from the one stage table
// (stage_table.h), passing preallocated buffers through lock-free SPSC rings.
//
//   capture --Frame ring[c]--> detect c --blob slot pool[c]--> identify --result pool--> publish
//      ^                          |                          (match by sequence,  (OutputSinks)
//      +------ return ring[c] ----+ (camera buffer back       pairs + N-view merge,
//                                    right after detection)   identify, angles)
//
// Ownership: a camera buffer (Frame) belongs to the capture thread, which alone calls
// release(); a detector hands every Frame back through its return ring. Blob slots and
// message slots live in rt::SlotPools (one producer, one consumer each). Everything is
// allocated at start(); the stage loops allocate nothing, take no lock, log nothing.
// Drop policy (the capture never blocks): each consumer drains its input and works on
// the NEWEST item, returning the older ones (counted as skipped); a producer whose
// consumer has stalled long enough to hold every slot drops the incoming item (counted).
// Matching: hal::FramePairer (one frame of every camera) by trigger sequence (tolerance 0) or, for
// free-running cameras, by sensor timestamp within PipelineOptions::pair_tolerance_us (unmatched
// frames counted).
// Latency: every sample is measured from the frame's trigger timestamp (Frame.timestamp_ns)
// on CLOCK_MONOTONIC: detect done, identify done, published (end to end), into
// LatencyHistograms that any thread may read while the pipeline runs.
// Health: health(), frames_published() and last_publish_ns() may be read from any thread.
// Sources: pipeline.cpp (setup, start/stop), capture_stage.cpp, processing_stages.cpp
// (detect, identify, publish loops), pipeline_stats.cpp (health, stats).
#pragma once

#include <array>
#include <atomic>
#include <cstdint>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "core/camera_set.h"
#include "core/expected.h"
#include "core/latency_stats.h"
#include "hal/camera.h"
#include "hal/frame_pairer.h"
#include "pipeline/doorbell.h"
#include "pipeline/frame_result_builder.h"
#include "pipeline/latency_histogram.h"
#include "pipeline/publish/output_sink.h"
#include "pipeline/stage_counters.h"
#include "pipeline/stage_table.h"
#include "pipeline/timestamp_check.h"
#include "rt/counter.h"
#include "rt/slot_pool.h"
#include "rt/spsc_ring.h"
#include "rt/thread.h"
#include "track/frame_processor.h"

namespace mocap::pipeline {

enum class TriggerPacing : std::uint8_t {
  kPeriodic,  // software trigger every 1/trigger_rate_hz (absolute deadlines, no drift)
  kLockstep,  // next trigger once the previous frame was published or dropped, and at
              // most at trigger_rate_hz (replays, tests: lossless)
};

enum class PairBy : std::uint8_t {
  kSequence,   // trigger sequence numbers must match (triggered cameras)
  kTimestamp,  // sensor timestamps within pair_tolerance_us (free-running cameras)
};

// Called on the identify thread with every processed frame (tests, recording).
class FrameObserver {
 public:
  virtual ~FrameObserver() = default;
  virtual void observe(std::uint64_t sequence, std::int64_t capture_ns,
                       const FrameOutput& out) noexcept = 0;
};

// Called on the capture thread with every frame a camera delivered (missing replay frames
// included), right after it was dequeued and before it goes to its detector: `mocap
// record` copies the images here (pipeline/record). Must be noexcept, allocation-free and
// return quickly (periodic pacing: it must never wait; lockstep pacing may wait briefly,
// as the trigger does).
class FrameTap {
 public:
  virtual ~FrameTap() = default;
  virtual void on_frame(int camera, const hal::Frame& frame) noexcept = 0;
};

// Called on each stage thread right before its loop starts and right after it ends
// (tests count the thread's heap allocations in between).
class StageHooks {
 public:
  virtual ~StageHooks() = default;
  virtual void on_loop_start(StageId stage) noexcept = 0;
  virtual void on_loop_end(StageId stage) noexcept = 0;
};

struct PipelineOptions {
  StageTable stages{};             // the rule per stage kind + per-camera detect overrides
  int cpu_count = 0;               // CPUs the detect rule spreads over; 0: this machine's (online)
  bool realtime = true;            // apply the table's CPU pinning and SCHED_FIFO (fallback noted)
  bool lock_memory = true;         // mlockall (fallback noted)
  double trigger_rate_hz = 100.0;  // software-triggered cameras
  TriggerPacing pacing = TriggerPacing::kPeriodic;
  std::uint64_t max_frames = 0;  // stop triggering after this many (0: unlimited)
  // Longest wait for a triggered frame; the capture also never waits past the next
  // trigger, so a stalled camera cannot slow the other one down.
  int dequeue_timeout_ms = 20;
  PairBy pair_by = PairBy::kSequence;
  // kTimestamp only: two frames pair when their timestamps differ by at most this; must
  // be below half the frame period.
  std::int64_t pair_tolerance_us = 1000;
  FrameObserver* observer = nullptr;
  StageHooks* hooks = nullptr;
  FrameTap* tap = nullptr;  // `mocap record`: every delivered frame, capture thread
};

// A cheap view of the running pipeline for a supervisor (systemd watchdog, status line):
// health() reads only atomics (no lock, no allocation; ~2 k relaxed loads for p99).
struct PipelineHealth {
  std::uint64_t frames_triggered = 0;
  std::uint64_t frames_published = 0;
  // Triggered frames known to be lost (never published): the sum of the sequence-level
  // drop counters (frames_unpaired + identify_skipped + identify_no_slot + publish_skipped).
  std::uint64_t frames_dropped = 0;
  double fps = 0.0;     // publish rate over the last ~16 frames; 0 after 1 s without one
  double p99_us = 0.0;  // trigger-to-publish p99 since start()
  double max_us = 0.0;  // trigger-to-publish max since start()
  std::int64_t last_publish_ns = 0;  // CLOCK_MONOTONIC; 0: nothing published yet
  int camera_count = 0;              // entries [0, camera_count) of the arrays below
  // Per camera: time since camera c last delivered a frame.
  std::array<std::int64_t, kMaxCameras> camera_silent_ms{};
  // Per camera: frames whose blobs did not all fit (an image full of blobs: the detector's
  // run or blob capacity overflowed; detect_camN_frames_overflow) and camera clock steps
  // (timestamp_backwards_camN + timestamp_jumps_camN).
  std::array<std::uint64_t, kMaxCameras> detect_overflow_frames{};
  std::array<std::uint64_t, kMaxCameras> timestamp_steps{};
  // Summed over the output sinks (OutputCounters): frames a transport refused, and frames
  // a slow sink's drop-oldest queue dropped.
  std::uint64_t output_failures = 0;
  std::uint64_t output_dropped = 0;
};

struct PipelineStats {
  double duration_s = 0.0;
  std::uint64_t triggered = 0;
  std::uint64_t published = 0;
  double fps = 0.0;  // published / duration
  // (name, summary): detect<k>/identify/publish are latencies from the trigger
  // ("publish" is trigger-to-publish, end to end); *_work are the stage's own times.
  std::vector<std::pair<std::string, LatencyStats>> latency;
  std::vector<std::pair<std::string, std::uint64_t>> counters;
};

class Pipeline {
 public:
  // `cameras` (2..kMaxCameras, in rig order: as many as the processor's rig has) are
  // configured but not started (the pipeline starts and stops them and drives them from
  // its capture thread); sinks and cameras must outlive the pipeline.
  static Expected<std::unique_ptr<Pipeline>> create(FrameProcessor processor,
                                                    std::vector<hal::Camera*> cameras,
                                                    std::vector<publish::OutputSink*> sinks,
                                                    const PipelineOptions& options);
  ~Pipeline();
  Pipeline(const Pipeline&) = delete;
  Pipeline& operator=(const Pipeline&) = delete;

  // Allocates every ring and slot, starts the cameras and the 3 + cameras threads. The
  // fallbacks taken (no SCHED_FIFO, no mlockall, no pinning) are in notes().
  Expected<void> start();
  // Stops triggering, joins every thread (each wakes within ~20 ms), returns every
  // buffer to its camera and stops the cameras. Idempotent.
  void stop() noexcept;
  bool running() const noexcept { return running_; }
  // True once max_frames frames were triggered and every one was published or dropped.
  bool finished() const noexcept;

  const std::vector<std::string>& notes() const noexcept { return notes_; }

  // Health, any thread (see PipelineHealth) except concurrently with start(), which
  // rebuilds the counters. Zeroes before the first start().
  PipelineHealth health() const noexcept;
  std::uint64_t frames_published() const noexcept {
    // acquire: pairs with the publish thread's release increment, so last_publish_ns()
    // read after this is at least as recent as the publish counted here.
    return published_.load(std::memory_order_acquire);
  }
  std::int64_t last_publish_ns() const noexcept {
    // relaxed: an independent timestamp; ordering is given by frames_published().
    return last_publish_ns_.load(std::memory_order_relaxed);
  }

  // The owner thread (the one calling start/stop), also while running: every value is
  // read atomically, values at slightly different instants. Report time: allocates.
  PipelineStats stats() const;
  // The trigger-to-publish histogram (any thread; periodic interval reports).
  const LatencyHistogram* end_to_end() const noexcept { return lat_ ? &lat_->publish : nullptr; }
  const FrameProcessor& processor() const noexcept { return processor_; }
  int camera_count() const noexcept { return static_cast<int>(cameras_.size()); }
  // The resolved stage of thread `id` (stage table rule and overrides applied).
  const ResolvedStage& stage(StageId id) const noexcept { return plan_[index(id)]; }

 private:
  struct BlobSlot {
    detect::BlobList blobs;
    std::uint64_t sequence = 0;
    std::int64_t capture_ns = 0;
    bool present = false;
  };
  struct MsgSlot {
    publish::FrameResult frame;  // the frame's whole result, for every output sink
  };
  struct Counters {
    rt::Counter triggered, trigger_errors, dequeue_timeouts[kMaxCameras], dequeue_errors;
    rt::Counter trigger_overruns;     // trigger periods skipped (capture late by >= 1 period)
    rt::Counter trigger_late_max_us;  // latest trigger vs its deadline
    rt::Counter capture_ring_full[kMaxCameras], release_errors;
    rt::Counter camera_max_silence_us[kMaxCameras];  // longest interval without a frame
    // Camera clock steps (TimestampCheck verdicts), capture thread.
    rt::Counter timestamp_backwards[kMaxCameras], timestamp_jumps[kMaxCameras];
    rt::Counter detect_skipped[kMaxCameras], detect_no_slot[kMaxCameras];
    rt::Counter frames_unpaired;  // sequences that never formed a pair (identify)
    rt::Counter identify_skipped, identify_no_slot;
    rt::Counter frames_without_result;  // processed, but not every body found
    rt::Counter publish_skipped, sink_failures;
    // The per-frame libraries' own counters (stage_counters.h), written every frame:
    // each writer thread's on cache lines of its own (no false sharing between cores).
    struct alignas(64) DetectLibrary {  // detect c
      DetectorMirror detector;
      rt::Counter blobs;  // blobs handed to identify
    };
    DetectLibrary detect_library[kMaxCameras];
    struct alignas(64) IdentifyLibrary {  // identify
      StereoMirror stereo;
      IdentifyMirror identify;
      ChainMirror chain;        // zero without a model
      CoverageMirror coverage;  // per joint
    };
    IdentifyLibrary identify_library;
  };
  struct Latencies {
    LatencyHistogram detect[kMaxCameras], detect_work[kMaxCameras];
    LatencyHistogram identify, identify_work, publish, sink_work;
    std::unique_ptr<LatencyHistogram[]> sink_work_each;  // one per sink, in sinks_ order
  };

  static constexpr std::int64_t kIdleWaitNs = 10'000'000;  // stages re-check stop this often
  static constexpr std::int64_t kLockstepTimeoutNs = 1'000'000'000;

  Pipeline(FrameProcessor processor, std::vector<hal::Camera*> cameras,
           std::vector<publish::OutputSink*> sinks, const PipelineOptions& options);

  // The stage loops (capture_stage.cpp, processing_stages.cpp).
  void capture_loop() noexcept;
  void detect_loop(int camera) noexcept;
  void identify_loop() noexcept;
  void publish_loop() noexcept;
  void release_returned() noexcept;
  // trigger_ns: host time of the last software trigger (0: free-running cameras).
  void on_frame_received(int camera, const hal::Frame& frame, std::int64_t trigger_ns) noexcept;
  void retire(std::uint64_t sequence) noexcept;
  bool stopping() const noexcept { return stop_.load(std::memory_order_acquire); }
  void drain_after_join() noexcept;

  FrameProcessor processor_;
  std::vector<hal::Camera*> cameras_;  // 2..kMaxCameras, fixed at create()
  std::vector<publish::OutputSink*> sinks_;
  PipelineOptions options_;
  std::array<ResolvedStage, kMaxStages> plan_{};  // per thread (index()), at create()
  std::vector<std::string> notes_;
  bool running_ = false;

  // Built at start().
  std::vector<std::unique_ptr<rt::SpscRing<hal::Frame>>> to_detect_, returned_;
  std::vector<std::unique_ptr<rt::SlotPool<BlobSlot>>> blob_pools_;
  std::unique_ptr<rt::SlotPool<MsgSlot>> msg_pool_;
  std::unique_ptr<hal::FramePairer> pairer_;
  std::unique_ptr<FrameOutput> out_;
  std::unique_ptr<Counters> counters_;
  std::unique_ptr<Latencies> lat_;
  std::array<TimestampCheck, kMaxCameras> clock_checks_{};  // capture thread (set at loop start)
  std::array<Doorbell, kMaxStages> bells_{};
  std::vector<rt::RtThread> threads_;
  std::int64_t start_ns_ = 0, stop_ns_ = 0;

  std::atomic<bool> stop_{false};
  std::atomic<bool> triggering_done_{false};
  std::atomic<std::uint64_t> published_{0};
  std::atomic<std::int64_t> last_publish_ns_{0};
  std::atomic<std::int64_t> publish_period_ns_{0};             // EMA, publish thread writes
  std::atomic<std::int64_t> last_frame_ns_[kMaxCameras] = {};  // capture thread writes
  // First sequence the capture thread dequeued (+1; 0: none yet): the start of the gaps.
  std::atomic<std::uint64_t> first_sequence_{0};
  // Highest sequence the identify/publish path has finished with (+1; 0: none).
  std::atomic<std::uint64_t> retired_{0};
};

}  // namespace mocap::pipeline
