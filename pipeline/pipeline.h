// Design: the live real-time pipeline: five pinned threads (stage_table.h) passing
// preallocated buffers through lock-free SPSC rings.
//
//   capture --Frame ring[c]--> detect c --blob slot pool[c]--> identify --msg pool--> publish
//      ^                          |                             (pair by sequence,   (sinks)
//      +------ return ring[c] ----+ (camera buffer back          stereo, identify,
//                                    right after detection)      angles)
//
// Ownership: a camera buffer (Frame) belongs to the capture thread, which alone calls
// release(); a detector hands every Frame back through its return ring. Blob slots and
// message slots live in rt::SlotPools (one producer, one consumer each). Everything is
// allocated at start(); the stage loops allocate nothing, take no lock, log nothing.
// Drop policy (the capture never blocks): each consumer drains its input and works on
// the NEWEST item, returning the older ones (counted as skipped); a producer whose
// consumer has stalled long enough to hold every slot drops the incoming item (counted).
// Pairing: FramePairer by trigger sequence (tolerance 0; unmatched frames counted).
// Latency: every sample is measured from the frame's trigger timestamp (Frame.timestamp_ns)
// on CLOCK_MONOTONIC: detect done, identify done, published (end to end).
// Health: frames_published() / last_publish_ns() may be read from any thread.
#pragma once

#include <array>
#include <atomic>
#include <cstdint>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "core/expected.h"
#include "core/latency_stats.h"
#include "hal/camera.h"
#include "hal/frame_pairer.h"
#include "hal/rt/counter.h"
#include "hal/rt/slot_pool.h"
#include "hal/rt/spsc_ring.h"
#include "hal/rt/thread.h"
#include "pipeline/doorbell.h"
#include "pipeline/joints_sink.h"
#include "pipeline/stage_table.h"
#include "track/frame_processor.h"

namespace mocap::pipeline {

enum class TriggerPacing : std::uint8_t {
  kPeriodic,  // software trigger every 1/trigger_rate_hz (absolute deadlines, no drift)
  kLockstep,  // next trigger once the previous frame was published or dropped, and at
              // most at trigger_rate_hz (replays, tests: lossless)
};

// Called on the identify thread with every processed frame (tests, recording).
class FrameObserver {
 public:
  virtual ~FrameObserver() = default;
  virtual void observe(std::uint64_t sequence, std::int64_t capture_ns,
                       const FrameOutput& out) noexcept = 0;
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
  std::array<StageSpec, kStageCount> stages = kDefaultStages;
  bool realtime = true;            // apply the table's CPU pinning and SCHED_FIFO (fallback noted)
  bool lock_memory = true;         // mlockall (fallback noted)
  double trigger_rate_hz = 100.0;  // software-triggered cameras
  TriggerPacing pacing = TriggerPacing::kPeriodic;
  std::uint64_t max_frames = 0;  // stop triggering after this many (0: unlimited)
  int dequeue_timeout_ms = 20;
  std::size_t latency_capacity = 1u << 16;  // samples kept per statistic (max always exact)
  FrameObserver* observer = nullptr;
  StageHooks* hooks = nullptr;
};

struct PipelineStats {
  double duration_s = 0.0;
  std::uint64_t triggered = 0;
  std::uint64_t published = 0;
  double fps = 0.0;  // published / duration
  // (name, summary): detect0/detect1/identify/publish are latencies from the trigger;
  // *_work are the stage's own processing times.
  std::vector<std::pair<std::string, LatencySummary>> latency;
  std::vector<std::pair<std::string, std::uint64_t>> counters;
};

class Pipeline {
 public:
  // `cameras` are configured but not started (the pipeline starts and stops them and
  // drives them from its capture thread); sinks and cameras must outlive the pipeline.
  static Expected<std::unique_ptr<Pipeline>> create(FrameProcessor processor,
                                                    std::array<hal::Camera*, 2> cameras,
                                                    std::vector<JointsSink*> sinks,
                                                    const PipelineOptions& options);
  ~Pipeline();
  Pipeline(const Pipeline&) = delete;
  Pipeline& operator=(const Pipeline&) = delete;

  // Allocates every ring and slot, starts the cameras and the five threads. The
  // fallbacks taken (no SCHED_FIFO, no mlockall, no pinning) are in notes().
  Expected<void> start();
  // Stops triggering, joins every thread (each wakes within ~20 ms), returns every
  // buffer to its camera and stops the cameras. Idempotent.
  void stop() noexcept;
  bool running() const noexcept { return running_; }
  // True once max_frames frames were triggered and every one was published or dropped.
  bool finished() const noexcept;

  const std::vector<std::string>& notes() const noexcept { return notes_; }

  // Health, any thread.
  std::uint64_t frames_published() const noexcept {
    // acquire: pairs with the publish thread's release increment, so last_publish_ns()
    // read after this is at least as recent as the publish counted here.
    return published_.load(std::memory_order_acquire);
  }
  std::int64_t last_publish_ns() const noexcept {
    // relaxed: an independent timestamp; ordering is given by frames_published().
    return last_publish_ns_.load(std::memory_order_relaxed);
  }

  // After stop() (or from the owner thread while running: counters are approximate).
  PipelineStats stats() const;
  const FrameProcessor& processor() const noexcept { return processor_; }

 private:
  struct BlobSlot {
    detect::BlobList blobs;
    std::uint64_t sequence = 0;
    std::int64_t capture_ns = 0;
    bool present = false;
  };
  struct MsgSlot {
    client::JointsMessage msg;
  };
  struct Counters {
    rt::Counter triggered, trigger_errors, dequeue_timeouts, dequeue_errors;
    rt::Counter capture_ring_full[2], release_errors;
    rt::Counter detect_skipped[2], detect_no_slot[2];
    rt::Counter identify_skipped, identify_no_slot;
    rt::Counter publish_skipped, sink_failures;
  };
  struct Latencies {
    LatencyRecorder detect[2], detect_work[2], identify, identify_work, publish, sink_work;
  };

  Pipeline(FrameProcessor processor, std::array<hal::Camera*, 2> cameras,
           std::vector<JointsSink*> sinks, const PipelineOptions& options);

  void capture_loop() noexcept;
  void detect_loop(int camera) noexcept;
  void identify_loop() noexcept;
  void publish_loop() noexcept;
  void release_returned() noexcept;
  void retire(std::uint64_t sequence) noexcept;
  bool stopping() const noexcept { return stop_.load(std::memory_order_acquire); }
  void drain_after_join() noexcept;

  FrameProcessor processor_;
  std::array<hal::Camera*, 2> cameras_;
  std::vector<JointsSink*> sinks_;
  PipelineOptions options_;
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
  std::array<Doorbell, kStageCount> bells_{};
  std::vector<rt::RtThread> threads_;
  std::int64_t start_ns_ = 0, stop_ns_ = 0;

  std::atomic<bool> stop_{false};
  std::atomic<bool> triggering_done_{false};
  std::atomic<std::uint64_t> published_{0};
  std::atomic<std::int64_t> last_publish_ns_{0};
  // Highest sequence the identify/publish path has finished with (+1; 0: none).
  std::atomic<std::uint64_t> retired_{0};
};

}  // namespace mocap::pipeline
