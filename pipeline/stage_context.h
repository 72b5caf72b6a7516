// Design: what the stage threads of the live pipeline share, and the buffers they pass.
//   - StageContext: the options, the stop flag, one Doorbell per thread, the sequences
//     (the first one captured, the highest one retired: lockstep pacing) and the frame
//     ledger (how many frames each stage handed on: Pipeline::finished()). It is the only state
//     more than one stage writes (retire(): identify and publish), and holds only atomics.
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
#include "pipeline/pipeline_options.h"
#include "pipeline/publish/frame_result.h"
#include "pipeline/stage_table.h"
#include "rt/doorbell.h"
#include "stereo/undistorted_blobs.h"

namespace mocap::pipeline {

// An idle stage re-checks its stop flag at least this often.
inline constexpr std::int64_t kIdleWaitNs = 10'000'000;

struct BlobSlot {
  detect::BlobList blobs;
  UndistortedStore undistorted;  // the blobs undistorted by the detect stage (received < 0: not)
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
  rt::Doorbell& bell(StageId id) noexcept { return bells_[index(id)]; }

  // Before the threads start (no thread runs: relaxed).
  void reset() noexcept {
    stop_.store(false, std::memory_order_relaxed);
    capture_done_.store(false, std::memory_order_relaxed);
    identify_done_.store(false, std::memory_order_relaxed);
    end_sequence_.store(0, std::memory_order_relaxed);
    for (auto& n : to_detect_) n.store(0, std::memory_order_relaxed);
    for (auto& n : detected_) n.store(0, std::memory_order_relaxed);
    to_publish_.store(0, std::memory_order_relaxed);
    published_.store(0, std::memory_order_relaxed);
    first_sequence_.store(0, std::memory_order_relaxed);
    retired_.store(0, std::memory_order_relaxed);
  }
  void request_stop() noexcept {
    // release: the stage threads' acquire loads see everything before the stop request.
    stop_.store(true, std::memory_order_release);
    for (rt::Doorbell& b : bells_) b.ring();
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

  // The frame ledger: how the run's end is known exactly. The capture counts the frames
  // it hands to each detect stage and then declares its end (no frame after it); each
  // detect stage counts the frames of its input it is done with (handed to identify,
  // skipped or dropped); identify, once both counts agree for every camera, has received
  // every frame there will be: it settles the sets still pending and declares its end with
  // the count of messages it handed to publish; publish counts the messages it is done
  // with. The run is drained when the last two agree.
  void note_handed_to_detect(int camera) noexcept {  // capture thread
    // relaxed: a single writer; read after capture_done() (acquire), which it precedes.
    to_detect_[static_cast<std::size_t>(camera)].fetch_add(1, std::memory_order_relaxed);
  }
  void note_detected(int camera) noexcept {  // detect stage `camera`
    // release: identify's acquire load that sees the count then sees the blob slot.
    detected_[static_cast<std::size_t>(camera)].fetch_add(1, std::memory_order_release);
  }
  // Capture thread: no frame is handed on from now (max_frames reached or a replay's end,
  // and the tail taken). end_sequence: the highest sequence dequeued + 1.
  void set_capture_done(std::uint64_t end_sequence) noexcept {
    end_sequence_.store(end_sequence, std::memory_order_relaxed);  // published below
    // release: a thread that sees capture_done() sees the ledger and end_sequence.
    capture_done_.store(true, std::memory_order_release);
    bell(StageId::kIdentify).ring();  // it settles the run's end without its idle wait
  }
  bool capture_done() const noexcept {
    return capture_done_.load(std::memory_order_acquire);  // see set_capture_done()
  }
  std::uint64_t end_sequence() const noexcept {            // after capture_done()
    return end_sequence_.load(std::memory_order_relaxed);  // see set_capture_done()
  }
  // Identify: every frame handed to the detect stages came out of them (capture_done()).
  bool detect_drained(int cameras) const noexcept {
    for (std::size_t c = 0; c < static_cast<std::size_t>(cameras); ++c) {
      // acquire: pairs with note_detected(); relaxed: see note_handed_to_detect().
      if (detected_[c].load(std::memory_order_acquire) !=
          to_detect_[c].load(std::memory_order_relaxed))
        return false;
    }
    return true;
  }
  void note_handed_to_publish() noexcept {  // identify
    // relaxed: a single writer; read after identify_done() (acquire), which it precedes.
    to_publish_.fetch_add(1, std::memory_order_relaxed);
  }
  void set_identify_done() noexcept {
    identify_done_.store(true, std::memory_order_release);  // publishes to_publish_
  }
  void note_published(std::uint64_t messages) noexcept {  // publish: published or skipped
    // release: drained() (acquire) sees what the sinks were given before.
    published_.fetch_add(messages, std::memory_order_release);
  }
  // Every frame of the run went through, or was counted as lost.
  bool drained() const noexcept {
    // acquire: see set_identify_done() and note_published().
    return identify_done_.load(std::memory_order_acquire) &&
           published_.load(std::memory_order_acquire) ==
               to_publish_.load(std::memory_order_relaxed);
  }

 private:
  const PipelineOptions& options_;
  std::array<rt::Doorbell, kMaxStages> bells_{};
  std::atomic<bool> stop_{false};
  std::atomic<bool> capture_done_{false};
  std::atomic<bool> identify_done_{false};
  std::atomic<std::uint64_t> end_sequence_{0};
  std::array<std::atomic<std::uint64_t>, kMaxCameras> to_detect_{};
  std::array<std::atomic<std::uint64_t>, kMaxCameras> detected_{};
  std::atomic<std::uint64_t> to_publish_{0};
  std::atomic<std::uint64_t> published_{0};
  std::atomic<std::uint64_t> first_sequence_{0};
  std::atomic<std::uint64_t> retired_{0};
};

}  // namespace mocap::pipeline
