// The stage objects on their own (pipeline/stage_context.h, publish_stage.h), without
// cameras: the publish stage hands the NEWEST waiting message to every sink and counts
// the older ones as skipped, counts a sink's refusal, retires each sequence it published
// (the ledger lockstep pacing waits on) and reports the counters it declares; the
// context's ledger only grows and keeps the first sequence it was told.
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <thread>

#include "pipeline/publish_stage.h"
#include "pipeline/stage_context.h"

namespace mocap::pipeline {
namespace {

// Publish thread only (writes), the test thread reads after join (atomics for TSan).
class SequenceSink final : public publish::OutputSink {
 public:
  explicit SequenceSink(bool accept) : accept_(accept) {}
  const char* name() const noexcept override { return accept_ ? "keep" : "refuse"; }
  bool publish(const publish::FrameResult& frame) noexcept override {
    last.store(frame.joints.sequence, std::memory_order_relaxed);
    calls.fetch_add(1, std::memory_order_relaxed);
    return accept_;
  }
  publish::OutputCounters counters() const noexcept override { return {}; }
  std::atomic<std::uint64_t> last{0}, calls{0};

 private:
  bool accept_;
};

void post(PublishStage& stage, StageContext& context, std::uint64_t sequence) {
  rt::SlotHandle h;
  ASSERT_TRUE(stage.input().acquire(h));
  stage.input()[h].frame.joints.sequence = sequence;
  stage.input()[h].frame.joints.capture_ns = monotonic_ns();
  stage.input().publish(h);
  context.bell(StageId::kPublish).ring();
}

std::uint64_t counter(const rt::CounterReport& r, const std::string& name) {
  for (const auto& [n, v] : r)
    if (n == name) return v;
  ADD_FAILURE() << "no counter " << name;
  return 0;
}

TEST(PublishStage, NewestMessageToEverySinkOlderOnesSkipped) {
  PipelineOptions options;
  StageContext context(options);
  context.reset();
  SequenceSink keep(true), refuse(false);
  auto stage = PublishStage::create(4, context, {&keep, &refuse});
  ASSERT_TRUE(stage.ok());
  PublishStage& s = **stage;
  for (std::uint64_t q = 10; q < 14; ++q) post(s, context, q);  // queued before it runs
  std::thread t([&] { s.run(); });
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(10);
  while (s.published() < 1 && std::chrono::steady_clock::now() < deadline)
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  post(s, context, 20);
  while (s.published() < 2 && std::chrono::steady_clock::now() < deadline)
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  context.request_stop();
  t.join();
  s.drain();
  EXPECT_EQ(s.published(), 2u);  // 13 (10..12 skipped), then 20
  EXPECT_EQ(keep.calls.load(), 2u);
  EXPECT_EQ(keep.last.load(), 20u);
  EXPECT_EQ(refuse.calls.load(), 2u);
  EXPECT_EQ(context.retired_plus_one(), 21u);
  EXPECT_EQ(s.frames_dropped(), 3u);
  EXPECT_GT(s.last_publish_ns(), 0);
  EXPECT_EQ(s.end_to_end().count(), 2u);
  EXPECT_EQ(s.sink_work(1).count(), 2u);
  rt::CounterReport r;
  s.report(r);
  EXPECT_EQ(counter(r, "published"), 2u);
  EXPECT_EQ(counter(r, "publish_skipped"), 3u);
  EXPECT_EQ(counter(r, "sink_failures"), 2u);  // the refusing sink, twice
}

TEST(StageContext, LedgerOnlyGrowsAndKeepsTheFirstSequence) {
  PipelineOptions options;
  StageContext context(options);
  context.reset();
  EXPECT_EQ(context.first_sequence_plus_one(), 0u);
  context.note_first_sequence(7);
  context.note_first_sequence(3);
  EXPECT_EQ(context.first_sequence_plus_one(), 8u);
  context.retire(9);
  context.retire(4);  // an older drop retired late: the ledger stays at 9
  EXPECT_EQ(context.retired_plus_one(), 10u);
  EXPECT_FALSE(context.triggering_done());
  context.set_triggering_done();
  EXPECT_TRUE(context.triggering_done());
  EXPECT_FALSE(context.stopping());
  context.request_stop();
  EXPECT_TRUE(context.stopping());
  context.reset();
  EXPECT_EQ(context.retired_plus_one(), 0u);
  EXPECT_FALSE(context.stopping());
}

}  // namespace
}  // namespace mocap::pipeline
