// The stage objects on their own (pipeline/stage_context.h, publish_stage.h), without
// cameras: the publish stage hands the NEWEST waiting message to every sink and counts
// the older ones as skipped, counts a sink's refusal, retires each sequence it published
// (the ledger lockstep pacing waits on) and reports the counters it declares; the
// context's ledger only grows and keeps the first sequence it was told. The capture stage
// triggers a camera with a trigger lead (a camera node's) through trigger_at(instant), at
// most its lead (and half a period) ahead of the instant, never after it, every frame.
#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <thread>

#include "pipeline/publish_stage.h"
#include "pipeline/stage_context.h"
#include "tests/pipeline/pipeline_fixture.h"

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

// Camera 0 of the simulated rig with a trigger lead: records each trigger_at() (the call
// time and the instant; the capture thread writes, the test reads after stop()) and
// fires the simulated trigger at once (what is checked is the capture stage's timing).
class LeadCamera final : public hal::Camera {
 public:
  LeadCamera(hal::Camera& inner, std::int64_t lead_ns) : inner_(inner), lead_ns_(lead_ns) {}
  const std::string& name() const noexcept override { return inner_.name(); }
  hal::CameraState state() const noexcept override { return inner_.state(); }
  Expected<void> configure(const hal::CameraConfig& c) override { return inner_.configure(c); }
  Expected<void> start() override { return inner_.start(); }
  void stop() noexcept override { inner_.stop(); }
  hal::CameraStatus trigger() noexcept override {
    plain.fetch_add(1, std::memory_order_relaxed);
    return inner_.trigger();
  }
  std::int64_t trigger_lead_ns() const noexcept override { return lead_ns_; }
  hal::CameraStatus trigger_at(std::int64_t at_ns) noexcept override {
    const std::size_t n = count.load(std::memory_order_relaxed);  // single writer
    if (n < calls.size()) {
      calls[n] = {monotonic_ns(), at_ns};
      count.store(n + 1, std::memory_order_release);
    }
    return inner_.trigger();
  }
  hal::CameraStatus dequeue(hal::Frame& f, int timeout_ms) noexcept override {
    return inner_.dequeue(f, timeout_ms);
  }
  hal::CameraStatus release(const hal::Frame& f) noexcept override { return inner_.release(f); }
  const hal::CameraConfig& config() const noexcept override { return inner_.config(); }
  const std::string& notice() const noexcept override { return inner_.notice(); }
  const hal::CameraCounters& counters() const noexcept override { return inner_.counters(); }

  struct Call {
    std::int64_t at_call_ns = 0, instant_ns = 0;
  };
  std::array<Call, 64> calls{};
  std::atomic<std::size_t> count{0};
  std::atomic<int> plain{0};

 private:
  hal::Camera& inner_;
  std::int64_t lead_ns_;
};

TEST(CaptureStage, ACameraWithALeadIsTriggeredAheadOfEachInstant) {
  // A 3 ms lead, and a 40 ms one (more than half the 50 ms period: half a period is used).
  // 20 Hz: the frames (sanitizers, a loaded machine) are retired well within a period, so
  // the lockstep capture is in time for most triggers.
  for (const std::int64_t lead_ns : {3'000'000LL, 40'000'000LL}) {
    test::SimRigFixture rig;
    LeadCamera lead(*rig.cams[0], lead_ns);
    std::vector<hal::Camera*> cams = rig.cameras();
    cams[0] = &lead;
    test::RecordingSink record(64);
    PipelineOptions opt = test::test_options();
    opt.max_frames = 20;
    opt.trigger_rate_hz = 20.0;
    opt.pacing = TriggerPacing::kLockstep;
    auto p = Pipeline::create(rig.processor(), cams, {&record}, opt);
    ASSERT_TRUE(p.ok()) << p.error().message;
    ASSERT_TRUE((*p)->start().ok());
    test::wait_finished(**p);
    (*p)->stop();
    EXPECT_EQ(record.count(), 20u);
    EXPECT_EQ(lead.plain.load(), 0);
    const std::size_t n = lead.count.load(std::memory_order_acquire);
    ASSERT_EQ(n, 20u);
    const std::int64_t used_ns = std::min<std::int64_t>(lead_ns, 25'000'000);
    std::vector<std::int64_t> ahead_ns;
    for (std::size_t i = 0; i < n; ++i) {
      const LeadCamera::Call& c = lead.calls[i];
      ahead_ns.push_back(c.instant_ns - c.at_call_ns);
      EXPECT_LE(ahead_ns.back(), used_ns) << "trigger " << i;  // at most the lead used
      if (i > 0) {
        EXPECT_GT(c.instant_ns, lead.calls[i - 1].instant_ns);
      }
    }
    // Ahead by about the lead: a trigger is posted late only when the capture thread
    // wakes late (then its instant is the posting time: it fires on arrival).
    std::nth_element(ahead_ns.begin(), ahead_ns.begin() + 10, ahead_ns.end());
    EXPECT_GE(ahead_ns[10], used_ns / 2) << "median lead";
  }
}

}  // namespace
}  // namespace mocap::pipeline
