// Design: see publish_stage.h.
#include "pipeline/publish_stage.h"

#include <utility>

namespace mocap::pipeline {

Expected<std::unique_ptr<PublishStage>> PublishStage::create(
    std::uint32_t input_depth, StageContext& context, std::vector<publish::OutputSink*> sinks) {
  auto pool =
      rt::SlotPool<MsgSlot>::create(input_depth + 2, [](std::uint32_t) { return MsgSlot{}; });
  if (!pool) return pool.error();
  return std::unique_ptr<PublishStage>(
      new PublishStage(context, std::move(sinks), std::move(pool).value()));
}

PublishStage::PublishStage(StageContext& context, std::vector<publish::OutputSink*> sinks,
                           rt::SlotPool<MsgSlot> input)
    : context_(context),
      sinks_(std::move(sinks)),
      input_(std::move(input)),
      sink_work_(std::make_unique<LatencyHistogram[]>(sinks_.size())) {}

void PublishStage::run() noexcept {
  context_.loop_start(StageId::kPublish);
  rt::Doorbell& bell = context_.bell(StageId::kPublish);
  std::uint64_t skipped_seen = 0;
  std::int64_t prev_publish_ns = 0;
  const PipelineOptions& options = context_.options();
  while (!context_.stopping()) {
    const std::uint32_t seen = bell.snapshot();
    rt::SlotHandle h{};
    const std::int64_t now = monotonic_ns();
    // Catch-up: the oldest message while it is fresh, else the next (options.fresh).
    if (!input_.pop_fresh(h, [&](const MsgSlot& m) { return options.fresh(m.origin_ns, now); })) {
      bell.wait(seen, kIdleWaitNs);
      continue;
    }
    std::uint64_t done = 1;                  // this message, and the older ones it replaced
    if (input_.skipped() != skipped_seen) {  // older messages replaced by this one
      done += input_.skipped() - skipped_seen;
      counters_.skipped.add(input_.skipped() - skipped_seen);
      skipped_seen = input_.skipped();
    }
    publish::FrameResult& frame = input_[h].frame;
    const std::int64_t origin_ns = input_[h].origin_ns;  // latencies start here, not at
                                                         // capture_ns (a replay's is old)
    const std::int64_t t0 = monotonic_ns();
    frame.joints.publish_ns = t0;
    std::int64_t t1 = t0;
    for (std::size_t i = 0; i < sinks_.size(); ++i) {
      if (!sinks_[i]->publish(frame)) counters_.sink_failures.add();
      const std::int64_t t = monotonic_ns();  // vDSO clock read, no syscall
      sink_work_[i].record(t - t1);
      t1 = t;
    }
    const std::uint64_t sequence = frame.joints.sequence;
    if (prev_publish_ns != 0) {  // publish period, exponential average over ~16 frames
      const std::int64_t ema = publish_period_ns_.load(std::memory_order_relaxed);
      const std::int64_t dt = t0 - prev_publish_ns;
      // relaxed: single writer; health() only wants a recent, untorn value.
      publish_period_ns_.store(ema == 0 ? dt : ema + (dt - ema) / 16, std::memory_order_relaxed);
    }
    prev_publish_ns = t0;
    work_.record(t1 - t0);
    end_to_end_.record(t0 - origin_ns);
    input_.release(h);
    // relaxed, then release: a reader that sees the new count (acquire) sees this time.
    last_publish_ns_.store(t0, std::memory_order_relaxed);
    published_.fetch_add(1, std::memory_order_release);
    context_.retire(sequence);
    context_.note_published(done);
  }
  context_.loop_end(StageId::kPublish);
}

void PublishStage::drain() noexcept {
  rt::SlotHandle h;
  while (input_.pop(h)) input_.release(h);
}

void PublishStage::report(rt::CounterReport& out) const {
  out.emplace_back("published", published());
  counters_.group.report(0, out);
}

}  // namespace mocap::pipeline
