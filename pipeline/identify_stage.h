// Design: the identify stage (one thread). It owns its input: one blob-slot pool per
// camera (sized by the stage table's ring depth + 2; each detect stage fills its own)
// and the hal::FramePairer that matches the cameras' slots of one trigger (by sequence,
// or by timestamp for free-running cameras). For every complete set it runs the rest of
// the frame (FrameProcessor::process_blobs: pairs + N-view merge, identification, joint
// angles) and fills a message slot of the publish stage.
// Drop policy: when a newer set is complete before the older one was processed, the
// older one is dropped (identify_skipped); when publish holds every message slot the
// result is dropped (identify_no_slot). Sequences that never formed a set (a camera, the
// capture, a detector or the pairer dropped them) are counted once each when the next
// set forms (frames_unpaired): sets form in increasing sequence order. Every dropped
// sequence is retired (StageContext::retire) so lockstep pacing goes on.
// Silent cameras (PipelineOptions::silent_after_ns, camera nodes the central does not
// trigger): the pairer completes the sets that waited for such a camera past its bound
// without it (its blobs empty, camera_present false); the wait is bounded by the next
// such deadline, so a silent node's cameras cost one bound, not a stall.
// Latencies (identify, and publish's end to end) start at camera 0's latency origin
// (hal::latency_origin_ns: the trigger, or a replay's delivery), carried in the slots;
// the published capture_ns is the frame's own timestamp (a replay's: the recording's).
// Its counters, the libraries' mirrored counters (stereo_*, identify_*, chain_*,
// coverage_*) and its two histograms have this thread as only writer. run() is the hot
// path: noexcept, allocation-free, lock-free, no logging.
#pragma once

#include <cstdint>
#include <memory>
#include <vector>

#include "core/expected.h"
#include "core/latency_histogram.h"
#include "hal/frame_pairer.h"
#include "pipeline/stage_context.h"
#include "pipeline/stage_counters.h"
#include "rt/counter_group.h"
#include "rt/slot_pool.h"
#include "track/frame_processor.h"
#include "track/labelled_markers.h"

namespace mocap::pipeline {

class IdentifyStage {
 public:
  static Expected<std::unique_ptr<IdentifyStage>> create(std::uint32_t input_depth,
                                                         StageContext& context,
                                                         FrameProcessor& processor,
                                                         rt::SlotPool<MsgSlot>& out);

  void run() noexcept;  // the thread's body, until the context stops
  // After every thread was joined: every blob slot back to its pool.
  void drain() noexcept;

  // Camera c's detect stage fills this pool (its producer end).
  rt::SlotPool<BlobSlot>& input(int camera) noexcept {
    return *inputs_[static_cast<std::size_t>(camera)];
  }

  // Any thread.
  const LatencyHistogram& latency() const noexcept { return latency_; }  // from the trigger
  const LatencyHistogram& work() const noexcept { return work_; }
  // Sequences known to be lost here: unpaired, skipped, no message slot.
  std::uint64_t frames_dropped() const noexcept {
    return counters_.frames_unpaired.get() + counters_.skipped.get() + counters_.no_slot.get();
  }
  void report(rt::CounterReport& out) const;  // report time

 private:
  IdentifyStage(StageContext& context, FrameProcessor& processor, rt::SlotPool<MsgSlot>& out,
                hal::FramePairer pairer);
  void count_unpaired(std::uint64_t sequence) noexcept;
  void release_set(const hal::FramePair& set) noexcept;
  int first_present(const hal::FramePair& set) const noexcept;  // not kAbsentHandle
  std::uint64_t sequence_of(const hal::FramePair& set) const noexcept {
    const int c = first_present(set);
    return (*inputs_[static_cast<std::size_t>(c)])[set.cam[c].handle].sequence;
  }
  std::int64_t origin_of(const hal::FramePair& set) const noexcept {  // the latencies' start
    const int c = first_present(set);
    return (*inputs_[static_cast<std::size_t>(c)])[set.cam[c].handle].origin_ns;
  }
  void process(const hal::FramePair& set) noexcept;
  // The run's input ended (StageContext's frame ledger): the pending sets are dropped and
  // counted, and identify declares its end.
  void settle() noexcept;

  StageContext& context_;
  FrameProcessor& processor_;
  rt::SlotPool<MsgSlot>& out_;
  const int cameras_;
  std::vector<std::unique_ptr<rt::SlotPool<BlobSlot>>> inputs_;
  hal::FramePairer pairer_;
  std::unique_ptr<FrameOutput> frame_;  // the frame being processed
  // make_frame_result()'s workspace (kMaxLabelledMarkers entries, ~20 KiB: on the heap)
  std::unique_ptr<LabelledMarkers> labelled_ = std::make_unique<LabelledMarkers>();
  std::uint64_t next_sequence_ = 0;  // the first sequence not yet accounted for
  bool counting_ = false;            // next_sequence_ is set

  struct alignas(64) Counters {
    rt::CounterGroup group;
    rt::NamedCounter frames_unpaired{group, "frames_unpaired"};       // never formed a set
    rt::NamedCounter skipped{group, "identify_skipped"};              // a newer set was complete
    rt::NamedCounter no_slot{group, "identify_no_slot"};              // publish held every slot
    rt::NamedCounter without_result{group, "frames_without_result"};  // not every body found
  } counters_;
  struct alignas(64) Library {
    StereoMirror stereo;
    MultiViewMirror multiview;  // zero with two cameras
    IdentifyMirror identify;
    ChainMirror chain;        // zero without a model
    CoverageMirror coverage;  // per joint
  } library_;
  LatencyHistogram latency_;
  LatencyHistogram work_;
};

}  // namespace mocap::pipeline
