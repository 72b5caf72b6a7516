// The stage objects on their own (pipeline/stage_context.h, publish_stage.h), without
// cameras: the publish stage hands the NEWEST waiting message to every sink and counts
// the older ones as skipped, counts a sink's refusal, retires each sequence it published
// (the ledger lockstep pacing waits on) and reports the counters it declares; the
// context's ledger only grows and keeps the first sequence it was told. The capture stage
// triggers a camera with a trigger lead (a camera node's) through trigger_at(instant), at
// most its lead (and half a period) ahead of the instant, never after it, every frame. A
// camera that delivers blobs (a camera node's) has no detect thread: the capture thread
// hands its blobs on, and the angles equal those of the same frames detected here.
#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <optional>
#include <thread>

#include "detect/blob_detector.h"
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
  EXPECT_FALSE(context.stopping());
  context.request_stop();
  EXPECT_TRUE(context.stopping());
  context.reset();
  EXPECT_EQ(context.retired_plus_one(), 0u);
  EXPECT_FALSE(context.stopping());
}

TEST(StageContext, TheRunIsDrainedWhenEveryStageHandedOnWhatItWasGiven) {
  PipelineOptions options;
  StageContext context(options);
  context.reset();
  // Two frames to camera 0's detect stage, one to camera 1's.
  context.note_handed_to_detect(0);
  context.note_handed_to_detect(0);
  context.note_handed_to_detect(1);
  context.note_detected(0);
  context.note_detected(1);
  EXPECT_FALSE(context.detect_drained(2));
  context.note_detected(0);
  EXPECT_TRUE(context.detect_drained(2));
  EXPECT_FALSE(context.capture_done());
  context.set_capture_done(42);
  EXPECT_TRUE(context.capture_done());
  EXPECT_EQ(context.end_sequence(), 42u);
  // Identify handed three messages on; publish is done with one, then with the other
  // two (one published, one it skipped for it).
  for (int i = 0; i < 3; ++i) context.note_handed_to_publish();
  context.note_published(1);
  EXPECT_FALSE(context.drained()) << "identify has not declared its end";
  context.set_identify_done();
  EXPECT_FALSE(context.drained()) << "two messages are still in publish's queue";
  context.note_published(2);
  EXPECT_TRUE(context.drained());
  context.reset();  // a new run starts from nothing
  EXPECT_FALSE(context.capture_done());
  EXPECT_FALSE(context.drained());
  EXPECT_TRUE(context.detect_drained(2));
  EXPECT_EQ(context.end_sequence(), 0u);
}

// Forwards every call to a simulated camera; the test cameras below change a few.
class WrappedCamera : public hal::Camera {
 public:
  explicit WrappedCamera(hal::Camera& inner) : inner_(inner) {}
  const std::string& name() const noexcept override { return inner_.name(); }
  hal::CameraState state() const noexcept override { return inner_.state(); }
  Expected<void> configure(const hal::CameraConfig& c) override { return inner_.configure(c); }
  Expected<void> start() override { return inner_.start(); }
  void stop() noexcept override { inner_.stop(); }
  hal::CameraStatus trigger() noexcept override { return inner_.trigger(); }
  hal::CameraStatus dequeue(hal::Frame& f, int timeout_ms) noexcept override {
    return inner_.dequeue(f, timeout_ms);
  }
  hal::CameraStatus release(const hal::Frame& f) noexcept override { return inner_.release(f); }
  const hal::CameraConfig& config() const noexcept override { return inner_.config(); }
  const std::string& notice() const noexcept override { return inner_.notice(); }
  const hal::CameraCounters& counters() const noexcept override { return inner_.counters(); }

 protected:
  hal::Camera& inner_;
};

// Camera 0 of the simulated rig with a trigger lead: records each trigger_at() (the call
// time and the instant; the capture thread writes, the test reads after stop()) and
// fires the simulated trigger at once (what is checked is the capture stage's timing).
class LeadCamera final : public WrappedCamera {
 public:
  LeadCamera(hal::Camera& inner, std::int64_t lead_ns) : WrappedCamera(inner), lead_ns_(lead_ns) {}
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

  struct Call {
    std::int64_t at_call_ns = 0, instant_ns = 0;
  };
  std::array<Call, 64> calls{};
  std::atomic<std::size_t> count{0};
  std::atomic<int> plain{0};

 private:
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

// A simulated camera whose frames also carry their blobs, detected in dequeue() with the
// tracker's own detector configuration (as a camera node's frames arrive detected).
class BlobCamera final : public WrappedCamera {
 public:
  explicit BlobCamera(hal::Camera& inner) : WrappedCamera(inner) {
    const hal::CameraConfig& c = inner.config();
    auto d = detect::BlobDetector::create(TrackerConfig{}.detect, c.width, c.height);
    EXPECT_TRUE(d.ok());
    for (int b = 0; b < c.buffer_count; ++b) lists_.push_back(d->make_blob_list());
    detector_.emplace(std::move(d).value());
  }
  bool delivers_blobs() const noexcept override { return true; }
  hal::CameraStatus dequeue(hal::Frame& f, int timeout_ms) noexcept override {
    const hal::CameraStatus s = inner_.dequeue(f, timeout_ms);
    if (s == hal::CameraStatus::kOk && !f.missing && !f.image.empty()) {
      detect::BlobList& list = lists_[f.buffer_index % lists_.size()];
      list.clear();
      (void)detector_->detect(f.image, list);
      f.blobs = &list;
    }
    return s;
  }

 private:
  std::optional<detect::BlobDetector> detector_;
  std::vector<detect::BlobList> lists_;
};

// Which stage threads ran (any thread writes, the test reads after stop()).
class StartedHooks final : public StageHooks {
 public:
  void on_loop_start(StageId s) noexcept override {
    started_[index(s)].store(true, std::memory_order_relaxed);
  }
  void on_loop_end(StageId) noexcept override {}
  bool started(StageId s) const { return started_[index(s)].load(std::memory_order_relaxed); }

 private:
  std::array<std::atomic<bool>, kMaxStages> started_{};
};

TEST(DetectStage, ACameraThatDeliversBlobsHasNoThreadAndTracksAsDetectedHere) {
  constexpr std::uint64_t kFrames = 15;
  std::vector<client::JointsMessage> got[2];
  for (const bool blobs : {false, true}) {
    test::SimRigFixture rig;
    std::vector<std::unique_ptr<BlobCamera>> wrapped;
    std::vector<hal::Camera*> cams = rig.cameras();
    if (blobs) {
      for (hal::Camera*& c : cams) {
        wrapped.push_back(std::make_unique<BlobCamera>(*c));
        c = wrapped.back().get();
      }
    }
    test::RecordingSink record(64);
    StartedHooks hooks;
    PipelineOptions opt = test::test_options();
    opt.max_frames = kFrames;
    opt.pacing = TriggerPacing::kLockstep;  // every frame, whatever the build's speed
    opt.hooks = &hooks;
    auto p = Pipeline::create(rig.processor(), cams, {&record}, opt);
    ASSERT_TRUE(p.ok()) << p.error().message;
    ASSERT_TRUE((*p)->start().ok());
    test::wait_finished(**p, 120.0);
    (*p)->stop();
    ASSERT_EQ(record.count(), kFrames);
    for (std::size_t i = 0; i < record.count(); ++i) got[blobs ? 1 : 0].push_back(record[i]);
    const PipelineStats st = (*p)->stats();
    EXPECT_TRUE(hooks.started(StageId::kCapture));
    EXPECT_TRUE(hooks.started(StageId::kIdentify));
    for (int c = 0; c < (*p)->camera_count(); ++c) {
      EXPECT_EQ(hooks.started(StageId::detect(c)), !blobs) << "camera " << c;
      EXPECT_GT(test::counter(st, rt::counter_name("detect_cam#_blobs", c)), 0u);
      EXPECT_EQ(test::counter(st, rt::counter_name("detect_cam#_frames", c)), blobs ? 0u : kFrames);
    }
  }
  // The same frames (the loop from its start, lockstep) give the same angles.
  for (std::uint64_t i = 0; i < kFrames; ++i) {
    const client::JointsMessage& a = got[0][i];
    const client::JointsMessage& b = got[1][i];
    ASSERT_EQ(a.joint_count, b.joint_count);
    EXPECT_GT(a.joint_count, 0);
    for (int j = 0; j < a.joint_count; ++j) {
      EXPECT_EQ(a.joints[j].valid, b.joints[j].valid) << "frame " << i << " joint " << j;
      for (int k = 0; k < 3; ++k) EXPECT_EQ(a.joints[j].a[k], b.joints[j].a[k]);
    }
  }
}

}  // namespace
}  // namespace mocap::pipeline
