// Design: the publish stage (one thread), the end of the pipeline. It owns its input,
// the pool of message slots the identify stage fills (sized by the stage table's ring
// depth + 2), and hands the NEWEST message to every output sink in turn (UDP, iceoryx,
// ROS 2, Foxglove, ...: publish/output_sink.h), older ones counted as skipped
// (publish_skipped); then the sequence is retired. It measures trigger-to-publish (the
// end-to-end latency, histogram "publish"), its own work and each sink's time, and keeps
// the published count, the last publish time and the publish period (an exponential
// average over ~16 frames) for the health view.
// run() is the hot path: noexcept, allocation-free, lock-free, no logging (sinks obey
// the same rules; slow encoders queue behind their own drop-oldest queues).
#pragma once

#include <atomic>
#include <cstdint>
#include <memory>
#include <vector>

#include "core/expected.h"
#include "core/latency_histogram.h"
#include "pipeline/publish/output_sink.h"
#include "pipeline/stage_context.h"
#include "rt/counter_group.h"
#include "rt/slot_pool.h"

namespace mocap::pipeline {

class PublishStage {
 public:
  static Expected<std::unique_ptr<PublishStage>> create(std::uint32_t input_depth,
                                                        StageContext& context,
                                                        std::vector<publish::OutputSink*> sinks);

  void run() noexcept;    // the thread's body, until the context stops
  void drain() noexcept;  // after every thread was joined

  // The identify stage fills this pool (its producer end).
  rt::SlotPool<MsgSlot>& input() noexcept { return input_; }

  // Any thread.
  std::uint64_t published() const noexcept {
    // acquire: pairs with the release increment, so last_publish_ns() read after this is
    // at least as recent as the publish counted here.
    return published_.load(std::memory_order_acquire);
  }
  std::int64_t last_publish_ns() const noexcept {
    // relaxed: an independent timestamp; ordering is given by published().
    return last_publish_ns_.load(std::memory_order_relaxed);
  }
  std::int64_t publish_period_ns() const noexcept {
    return publish_period_ns_.load(std::memory_order_relaxed);  // relaxed: untorn, recent
  }
  std::uint64_t frames_dropped() const noexcept { return counters_.skipped.get(); }
  const LatencyHistogram& end_to_end() const noexcept { return end_to_end_; }
  const LatencyHistogram& work() const noexcept { return work_; }
  const LatencyHistogram& sink_work(std::size_t sink) const noexcept { return sink_work_[sink]; }
  const std::vector<publish::OutputSink*>& sinks() const noexcept { return sinks_; }
  void report(rt::CounterReport& out) const;  // report time

 private:
  PublishStage(StageContext& context, std::vector<publish::OutputSink*> sinks,
               rt::SlotPool<MsgSlot> input);

  StageContext& context_;
  std::vector<publish::OutputSink*> sinks_;
  rt::SlotPool<MsgSlot> input_;

  struct alignas(64) Counters {
    rt::CounterGroup group;
    rt::NamedCounter skipped{group, "publish_skipped"};      // replaced by a newer message
    rt::NamedCounter sink_failures{group, "sink_failures"};  // a sink refused a frame
  } counters_;
  std::atomic<std::uint64_t> published_{0};
  std::atomic<std::int64_t> last_publish_ns_{0};
  std::atomic<std::int64_t> publish_period_ns_{0};  // EMA, this thread writes
  LatencyHistogram end_to_end_;                     // trigger to publish
  LatencyHistogram work_;                           // every sink, one frame
  std::unique_ptr<LatencyHistogram[]> sink_work_;   // per sink, in sinks_ order
};

}  // namespace mocap::pipeline
