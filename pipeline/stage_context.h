// Design: what the stage threads of the live pipeline share, and the buffers they pass.
//   - StageContext: the options, the stop flag, one Doorbell per thread and the sequence
//     ledger (the first sequence captured, the highest one retired, "triggering done"),
//     which lockstep pacing and Pipeline::finished() read. It is the only state more
//     than one stage writes (retire(): identify and publish), and holds only atomics.
//   - BlobSlot (detect c -> identify, one rt::SlotPool per camera) and MsgSlot
//     (identify -> publish): preallocated at start(), passed by handle.
// Every call is noexcept, lock-free and allocation-free; the memory orders are
// justified where each atomic is accessed.
#pragma once

#include <array>
#include <atomic>
#include <cstdint>

#include "core/clock.h"
#include "detect/blob.h"
#include "pipeline/doorbell.h"
#include "pipeline/pipeline_options.h"
#include "pipeline/publish/frame_result.h"
#include "pipeline/stage_table.h"

namespace mocap::pipeline {

// An idle stage re-checks its stop flag at least this often.
inline constexpr std::int64_t kIdleWaitNs = 10'000'000;

struct BlobSlot {
  detect::BlobList blobs;
  std::uint64_t sequence = 0;
  std::int64_t capture_ns = 0;  // the data's capture time (hal::Frame::timestamp_ns)
  std::int64_t origin_ns = 0;   // where its latencies start (hal::latency_origin_ns)
  bool present = false;         // false: the camera's frame was missing or empty
};

struct MsgSlot {
  publish::FrameResult frame;  // the frame's whole result, for every output sink
  std::int64_t origin_ns = 0;  // camera 0's latency origin: the end-to-end latency's start
};

class StageContext {
 public:
  explicit StageContext(const PipelineOptions& options) noexcept : options_(options) {}
  StageContext(const StageContext&) = delete;
  StageContext& operator=(const StageContext&) = delete;

  const PipelineOptions& options() const noexcept { return options_; }
  Doorbell& bell(StageId id) noexcept { return bells_[index(id)]; }

  // Before the threads start (no thread runs: relaxed).
  void reset() noexcept {
    stop_.store(false, std::memory_order_relaxed);
    triggering_done_.store(false, std::memory_order_relaxed);
    first_sequence_.store(0, std::memory_order_relaxed);
    retired_.store(0, std::memory_order_relaxed);
  }
  void request_stop() noexcept {
    // release: the stage threads' acquire loads see everything before the stop request.
    stop_.store(true, std::memory_order_release);
    for (Doorbell& b : bells_) b.ring();
  }
  bool stopping() const noexcept { return stop_.load(std::memory_order_acquire); }

  // The stage hooks (tests count a thread's allocations between them).
  void loop_start(StageId id) const noexcept {
    if (options_.hooks) options_.hooks->on_loop_start(id);
  }
  void loop_end(StageId id) const noexcept {
    if (options_.hooks) options_.hooks->on_loop_end(id);
  }

  // Capture thread: the first sequence it dequeued (the start of the gaps identify counts).
  void note_first_sequence(std::uint64_t sequence) noexcept {
    if (first_sequence_.load(std::memory_order_relaxed) != 0) return;  // single writer
    // release: stored before this frame enters any ring; identify reads it after
    // receiving a later frame through the rings (acquire), so it sees the value.
    first_sequence_.store(sequence + 1, std::memory_order_release);
  }
  // The first sequence + 1 (0: none yet).
  std::uint64_t first_sequence_plus_one() const noexcept {
    return first_sequence_.load(std::memory_order_acquire);  // see note_first_sequence()
  }

  // Identify or publish: the pipeline is done with `sequence` (published or dropped).
  void retire(std::uint64_t sequence) noexcept {
    // acq_rel CAS loop (two writers): the capture thread's acquire load in lockstep sees
    // a value only ever growing.
    std::uint64_t cur = retired_.load(std::memory_order_relaxed);
    while (cur < sequence + 1 &&
           !retired_.compare_exchange_weak(cur, sequence + 1, std::memory_order_acq_rel,
                                           std::memory_order_relaxed)) {
    }
    bell(StageId::kCapture).ring();
  }
  // The highest retired sequence + 1 (0: none).
  std::uint64_t retired_plus_one() const noexcept {
    return retired_.load(std::memory_order_acquire);  // pairs with retire()
  }

  // Capture thread: no more triggers (max_frames reached, or a replay's end).
  void set_triggering_done() noexcept {
    // release: finished() (acquire) then sees every counter written before.
    triggering_done_.store(true, std::memory_order_release);
  }
  bool triggering_done() const noexcept {
    return triggering_done_.load(std::memory_order_acquire);  // see set_triggering_done()
  }

 private:
  const PipelineOptions& options_;
  std::array<Doorbell, kMaxStages> bells_{};
  std::atomic<bool> stop_{false};
  std::atomic<bool> triggering_done_{false};
  std::atomic<std::uint64_t> first_sequence_{0};
  std::atomic<std::uint64_t> retired_{0};
};

}  // namespace mocap::pipeline
