// The live pipeline on the simulated stereo pair (functional checks only, never speed):
// frames are published in sequence order with correct joint angles (lockstep); a slow sink causes
// counted drops without blocking the capture and without publishing a frame twice;
// start/stop cycles; 0 heap allocations on every stage thread in the steady state; the
// health counters read from another thread only grow.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "pipeline/stats_report.h"
#include "sim/simulate.h"
#include "tests/pipeline/pipeline_fixture.h"
#include "tests/support/alloc_counter.h"

namespace mocap::pipeline {
namespace {

using test::counter;
using test::RecordingSink;
using test::shared_loop;
using test::SimRigFixture;

TEST(Pipeline, PublishesFramesInOrderWithTrueAngles) {
  SimRigFixture rig;
  RecordingSink sink(1000);
  PipelineOptions opt = test::test_options();
  opt.max_frames = 120;
  opt.pacing = TriggerPacing::kLockstep;  // lossless: the result does not depend on load
  auto p = Pipeline::create(rig.processor(), rig.cameras(), {&sink}, opt);
  ASSERT_TRUE(p.ok()) << p.error().message;
  ASSERT_TRUE((*p)->start().ok());
  test::wait_finished(**p);
  (*p)->stop();
  const PipelineStats st = (*p)->stats();
  EXPECT_EQ(st.triggered, 120u);
  ASSERT_EQ(sink.count(), 120u) << format_pipeline_stats(st);
  EXPECT_EQ(st.published, sink.count());

  const sim::SimScene& scene = shared_loop()->scene();
  std::size_t all_valid = 0;
  std::vector<double> errors_deg, hinge_offsets_rad;
  for (std::size_t i = 0; i < sink.count(); ++i) {
    const client::JointsMessage& m = sink[i];
    EXPECT_EQ(m.sequence, i);
    EXPECT_GE(m.publish_ns, m.capture_ns);
    ASSERT_EQ(m.joint_count, scene.joints_true.joints.size());
    bool valid = (m.flags & client::kFlagAllBodiesFound) != 0;
    const sim::SceneState& truth =
        shared_loop()->state(shared_loop()->frame_of_sequence(m.sequence));
    for (std::size_t j = 0; j < m.joint_count; ++j) {
      const client::JointRecord& r = m.joints[j];
      valid = valid && r.valid == 1;
      if (r.valid == 0) continue;
      EXPECT_GE(r.q[0], 0.0f);
      const JointSpec& js = scene.joints_true.joints[j];
      const Vec3 want =
          sim::joint_angles_rad(js, truth.T_world_body[static_cast<std::size_t>(js.parent_index)],
                                truth.T_world_body[static_cast<std::size_t>(js.child_index)]);
      if (js.type == JointType::kHinge) {
        // The hinge's zero differs between the solver and the simulator's truth by a
        // constant (see the report): compare the motion, i.e. the offset's spread.
        hinge_offsets_rad.push_back(
            std::remainder(static_cast<double>(r.a[0]) - want[0], 2.0 * M_PI));
        continue;
      }
      for (int k = 0; k < 3; ++k) {
        const double d = static_cast<double>(r.a[k]) - want[k];
        errors_deg.push_back(std::abs(std::remainder(d, 2.0 * M_PI)) * 180.0 / M_PI);
      }
    }
    all_valid += valid ? 1 : 0;
    // The rest of the frame's result reached the sink too (the output seam).
    const RecordingSink::ResultSummary& res = sink.result(i);
    EXPECT_EQ(res.body_count, static_cast<int>(scene.targets.bodies.size()));
    if ((m.flags & client::kFlagAllBodiesFound) != 0) {
      EXPECT_EQ(res.bodies_found, res.body_count);
      EXPECT_GE(res.marker_count, 3 * res.body_count);
      EXPECT_GE(res.point_count, res.marker_count);
    }
    if (res.body0_found) {
      const Vec3 t = truth.T_world_body[0].translation();
      EXPECT_NEAR(res.t0_mm[0], t.x(), 3.0);
      EXPECT_NEAR(res.t0_mm[2], t.z(), 3.0);
    }
  }
  // Some loop frames of the scenario are not fully identified (the same ones every
  // cycle, deterministic in lockstep: 56 of 120 complete here; a pose resting on partial
  // markers needs 4 markers, docs/identification.md). A large share must be complete.
  EXPECT_GT(all_valid * 3, sink.count()) << "angles valid in more than a third of the frames";
  ASSERT_FALSE(errors_deg.empty());
  std::sort(errors_deg.begin(), errors_deg.end());
  EXPECT_LT(errors_deg[errors_deg.size() / 2], 1.0) << "median angle error (deg)";
  EXPECT_LT(errors_deg[errors_deg.size() * 95 / 100], 5.0) << "95th percentile (deg)";
  ASSERT_FALSE(hinge_offsets_rad.empty());
  std::sort(hinge_offsets_rad.begin(), hinge_offsets_rad.end());
  const double offset = hinge_offsets_rad[hinge_offsets_rad.size() / 2];
  std::size_t hinge_ok = 0;
  for (double o : hinge_offsets_rad)
    hinge_ok += std::abs(std::remainder(o - offset, 2.0 * M_PI)) < 2.0 * M_PI / 180.0;
  EXPECT_GE(hinge_ok * 20, hinge_offsets_rad.size() * 19)
      << "hinge follows the true motion within 2 deg";
  // Latency statistics were recorded for every published frame.
  for (const auto& [name, l] : st.latency) {
    if (name == "publish") {
      EXPECT_EQ(l.count, st.published);
    }
  }
}

TEST(Pipeline, SlowSinkDropsAreCountedAndNothingIsPublishedTwice) {
  SimRigFixture rig;
  // 20 ms per message (50 messages/s) at 100 frames/s: the sink is the bottleneck, while
  // detection and identification keep up even under ThreadSanitizer (at 200 frames/s the
  // instrumented upstream stages dropped first, so the publish drops were not exercised).
  RecordingSink sink(1000, 20000);
  PipelineOptions opt = test::test_options();
  opt.max_frames = 100;
  opt.trigger_rate_hz = 100.0;
  auto p = Pipeline::create(rig.processor(), rig.cameras(), {&sink}, opt);
  ASSERT_TRUE(p.ok());
  ASSERT_TRUE((*p)->start().ok());
  test::wait_finished(**p);
  (*p)->stop();
  const PipelineStats st = (*p)->stats();
  // The capture ran every trigger: it never waited for the slow sink.
  EXPECT_EQ(st.triggered, 100u);
  EXPECT_EQ(rig.cams[0]->counters().frames.get(), 100u);
  EXPECT_EQ(rig.cams[1]->counters().frames.get(), 100u);
  EXPECT_LT(sink.count(), 100u);
  const std::uint64_t drops = counter(st, "publish_skipped") + counter(st, "identify_no_slot") +
                              counter(st, "identify_skipped") + counter(st, "detect0_skipped") +
                              counter(st, "detect0_no_slot") + counter(st, "capture_dropped_cam0");
  EXPECT_GT(drops, 0u) << format_pipeline_stats(st);
  EXPECT_GT(counter(st, "publish_skipped") + counter(st, "identify_no_slot"), 0u);
  for (std::size_t i = 1; i < sink.count(); ++i) EXPECT_GT(sink[i].sequence, sink[i - 1].sequence);
  EXPECT_EQ(counter(st, "release_errors"), 0u);
}

// A sink that stalls 35 ms on every 10th message (3.5 frames at 100 frames/s, 3.5 ms per
// message on average): the newest-first stages (catch_up_ns 0) drop the frames the stall
// held back; with every_frame (pipeline.every_frame) every frame is published, in order,
// later. With a catch-up bound (pipeline.catch_up_ms) the stages take the frames a stall
// held back while they are younger than the bound, and skip the older ones.
std::uint64_t stalled_sink_run(const PipelineOptions& base, RecordingSink& sink,
                               PipelineStats& st) {
  SimRigFixture rig;
  PipelineOptions opt = base;
  opt.max_frames = 100;
  opt.trigger_rate_hz = 100.0;
  auto p = Pipeline::create(rig.processor(), rig.cameras(), {&sink}, opt);
  EXPECT_TRUE(p.ok());
  if (!p.ok()) return 0;
  EXPECT_TRUE((*p)->start().ok());
  test::wait_finished(**p);
  (*p)->stop();
  st = (*p)->stats();
  return counter(st, "publish_skipped") + counter(st, "identify_skipped") +
         counter(st, "detect0_skipped") + counter(st, "detect1_skipped");
}

// Every frame the stages received reached the sink, in order (a loaded test machine may
// still drop at a full ring: counted once in frames_dropped, and explained by a ring's
// drop; the sequence then shows the gap).
void expect_every_frame_in_order(const RecordingSink& sink, const PipelineStats& st) {
  EXPECT_EQ(st.triggered, 100u);
  EXPECT_EQ(sink.count() + counter(st, "frames_dropped"), 100u) << format_pipeline_stats(st);
  // A set that lost a camera's frame at a full ring is never paired (frames_unpaired).
  const std::uint64_t ring_drops = counter(st, "identify_no_slot") +
                                   counter(st, "frames_unpaired") + counter(st, "detect0_no_slot") +
                                   counter(st, "detect1_no_slot");
  EXPECT_EQ(counter(st, "frames_dropped"), ring_drops) << format_pipeline_stats(st);
  for (std::size_t i = 1; i < sink.count(); ++i) EXPECT_GT(sink[i].sequence, sink[i - 1].sequence);
}

TEST(Pipeline, EveryFrameDelaysWhatAStallingSinkHeldBackAndLosesNothing) {
  RecordingSink newest_sink(1000, 35000, 10), ordered_sink(1000, 35000, 10);
  PipelineStats newest, ordered;
  PipelineOptions opt = test::test_options();
  opt.catch_up_ns = 0;
  EXPECT_GT(stalled_sink_run(opt, newest_sink, newest), 0u) << format_pipeline_stats(newest);
  opt.every_frame = true;
  EXPECT_EQ(stalled_sink_run(opt, ordered_sink, ordered), 0u) << format_pipeline_stats(ordered);
  expect_every_frame_in_order(ordered_sink, ordered);
}

TEST(Pipeline, CatchUpTakesWhatAShortStallHeldBackAndSkipsWhatALongOneMadeStale) {
  // Stalls of 35 ms against a bound of 500 ms: nothing is too old, nothing is skipped.
  RecordingSink short_sink(1000, 35000, 10);
  PipelineStats short_st;
  PipelineOptions opt = test::test_options();
  opt.catch_up_ns = 500'000'000;
  EXPECT_EQ(stalled_sink_run(opt, short_sink, short_st), 0u) << format_pipeline_stats(short_st);
  expect_every_frame_in_order(short_sink, short_st);
  // Stalls of 200 ms against a bound of 20 ms: the frames they held back are stale.
  RecordingSink long_sink(1000, 200000, 25);
  PipelineStats long_st;
  opt.catch_up_ns = 20'000'000;
  EXPECT_GT(stalled_sink_run(opt, long_sink, long_st), 0u) << format_pipeline_stats(long_st);
  EXPECT_LT(long_sink.count(), 100u);
  for (std::size_t i = 1; i < long_sink.count(); ++i)
    EXPECT_GT(long_sink[i].sequence, long_sink[i - 1].sequence);
}

TEST(Pipeline, StartStopRepeatedly) {
  SimRigFixture rig;
  RecordingSink sink(5000);
  PipelineOptions opt = test::test_options();
  auto p = Pipeline::create(rig.processor(), rig.cameras(), {&sink}, opt);
  ASSERT_TRUE(p.ok());
  std::uint64_t total = 0;
  for (int cycle = 0; cycle < 4; ++cycle) {
    ASSERT_TRUE((*p)->start().ok()) << "cycle " << cycle;
    EXPECT_FALSE((*p)->start().ok());  // already running
    std::this_thread::sleep_for(std::chrono::milliseconds(150));
    (*p)->stop();
    EXPECT_FALSE((*p)->running());
    const PipelineStats st = (*p)->stats();
    total += st.published;
    EXPECT_EQ(counter(st, "release_errors"), 0u);
    EXPECT_EQ(rig.cams[0]->state(), hal::CameraState::kConfigured);
  }
  (*p)->stop();  // idempotent
  EXPECT_EQ(sink.count(), total);
  EXPECT_GT(total, 0u);
}

class AllocationHooks final : public StageHooks {
 public:
  void on_loop_start(StageId s) noexcept override {
    start_[index(s)] = mocap::test::thread_allocation_count();
  }
  void on_loop_end(StageId s) noexcept override {
    allocations_[index(s)] = mocap::test::thread_allocation_count() - start_[index(s)];
    ended_[index(s)].store(true, std::memory_order_release);
  }
  std::uint64_t allocations(StageId s) const { return allocations_[index(s)]; }
  bool ended(StageId s) const { return ended_[index(s)].load(std::memory_order_acquire); }

 private:
  std::array<std::uint64_t, kMaxStages> start_{}, allocations_{};
  std::array<std::atomic<bool>, kMaxStages> ended_{};
};

// Every stage thread of a pipeline over `rig`'s cameras ran and allocated nothing.
void expect_stage_threads_do_not_allocate(SimRigFixture& rig, std::uint64_t frames) {
  RecordingSink sink(1000);
  AllocationHooks hooks;
  PipelineOptions opt = test::test_options();
  opt.hooks = &hooks;
  opt.max_frames = frames;
  // Lockstep: every frame reaches the sink however slow the build (TSan, a loaded CI);
  // at the trigger rate a sanitizer build drops frames and the count would be timing.
  opt.pacing = TriggerPacing::kLockstep;
  auto p = Pipeline::create(rig.processor(), rig.cameras(), {&sink}, opt);
  ASSERT_TRUE(p.ok()) << p.error().message;
  ASSERT_TRUE((*p)->start().ok());
  test::wait_finished(**p, 120.0);
  (*p)->stop();
  EXPECT_EQ(sink.count(), frames);
  // The multi-view merger's counters are reported with three or more cameras only.
  const PipelineStats st = (*p)->stats();
  const bool has_multiview = std::any_of(st.counters.begin(), st.counters.end(), [](const auto& c) {
    return c.first.rfind("multiview_", 0) == 0;
  });
  EXPECT_EQ(has_multiview, (*p)->camera_count() > 2);
  if (has_multiview) {
    EXPECT_EQ(counter(st, "multiview_frames"), counter(st, "identify_frames"));
    EXPECT_GT(counter(st, "multiview_points"), 0u);
  }
  std::vector<StageId> ids = {StageId::kCapture, StageId::kIdentify, StageId::kPublish};
  for (int c = 0; c < (*p)->camera_count(); ++c) ids.push_back(StageId::detect(c));
  for (StageId id : ids) {
    ASSERT_TRUE(hooks.ended(id)) << (*p)->stage(id).name;
    EXPECT_EQ(hooks.allocations(id), 0u) << (*p)->stage(id).name;
  }
}

TEST(Pipeline, StageThreadsDoNotAllocate) {
  SimRigFixture rig;
  expect_stage_threads_do_not_allocate(rig, 100);
}

TEST(Pipeline, FourCameraStageThreadsDoNotAllocate) {
  SimRigFixture rig(6, test::render_loop(4, 4));  // a short 4-camera loop
  ASSERT_EQ(rig.cams.size(), 4u);
  expect_stage_threads_do_not_allocate(rig, 30);
}

TEST(Pipeline, DetectStagesFollowTheTableRule) {
  SimRigFixture rig(6, test::render_loop(2, 4));
  RecordingSink sink(10);
  PipelineOptions opt = test::test_options();
  opt.cpu_count = 2;
  opt.stages.detect[3].cpu = -1;  // one camera's override
  auto p = Pipeline::create(rig.processor(), rig.cameras(), {&sink}, opt);
  ASSERT_TRUE(p.ok()) << p.error().message;
  const StageSpec& rule = kDefaultStages[static_cast<std::size_t>(StageKind::kDetect)];
  for (int c = 0; c < 3; ++c) {
    const ResolvedStage& s = (*p)->stage(StageId::detect(c));
    EXPECT_EQ(s.name, "mocap-detect" + std::to_string(c));
    EXPECT_EQ(s.cpu, (rule.cpu + c) % 2);
    EXPECT_EQ(s.fifo_priority, rule.fifo_priority);
  }
  EXPECT_EQ((*p)->stage(StageId::detect(3)).cpu, -1);
  // The camera count must be the rig's.
  std::vector<hal::Camera*> three = rig.cameras();
  three.pop_back();
  auto q = Pipeline::create(rig.processor(), three, {&sink}, opt);
  ASSERT_FALSE(q.ok());
  EXPECT_NE(q.error().message.find("the rig has 4"), std::string::npos) << q.error().message;
}

TEST(Pipeline, HealthCountersOnlyGrow) {
  SimRigFixture rig;
  RecordingSink sink(1000);
  PipelineOptions opt = test::test_options();
  opt.max_frames = 60;
  auto p = Pipeline::create(rig.processor(), rig.cameras(), {&sink}, opt);
  ASSERT_TRUE(p.ok());
  ASSERT_TRUE((*p)->start().ok());
  std::uint64_t last = 0;
  std::int64_t last_ns = 0;
  while (!(*p)->finished()) {
    const std::uint64_t n = (*p)->frames_published();
    const std::int64_t t = (*p)->last_publish_ns();
    EXPECT_GE(n, last);
    if (n > 0) {
      EXPECT_GT(t, 0);
      EXPECT_GE(t, last_ns);
    }
    last = n;
    last_ns = t;
    std::this_thread::sleep_for(std::chrono::microseconds(500));
  }
  (*p)->stop();
  EXPECT_EQ((*p)->frames_published(), sink.count());
}

TEST(Pipeline, SetupErrorsAreOneLine) {
  SimRigFixture rig(4);  // fewer buffers than detect ring depth + 2
  RecordingSink sink(10);
  auto p = Pipeline::create(rig.processor(), rig.cameras(), {&sink}, test::test_options());
  ASSERT_TRUE(p.ok());
  auto r = (*p)->start();
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.error().message.find("buffer_count"), std::string::npos) << r.error().message;
  EXPECT_EQ(r.error().message.find('\n'), std::string::npos);

  SimRigFixture rig2;
  PipelineOptions bad = test::test_options();
  bad.stages[StageKind::kIdentify].ring_depth = 1;
  auto q = Pipeline::create(rig2.processor(), rig2.cameras(), {&sink}, bad);
  ASSERT_FALSE(q.ok());
  EXPECT_NE(q.error().message.find("ring_depth"), std::string::npos);
  bad = test::test_options();
  bad.trigger_rate_hz = 0.0;
  EXPECT_FALSE(Pipeline::create(rig2.processor(), rig2.cameras(), {&sink}, bad).ok());
  bad.trigger_rate_hz = 1e-12;  // its period would overflow the nanosecond clock
  EXPECT_FALSE(Pipeline::create(rig2.processor(), rig2.cameras(), {&sink}, bad).ok());
}

TEST(Pipeline, StatsReportHasEveryStage) {
  PipelineStats s;
  s.duration_s = 2.0;
  s.triggered = 200;
  s.published = 190;
  s.fps = 95.0;
  s.latency = {{"detect0", LatencyStats{190, 1000.0, 2000.0, 2500.0, 3000.0, 1100.0}},
               {"publish", LatencyStats{190, 4000.0, 5000.0, 5500.0, 6000.0, 4100.0}}};
  s.counters = {{"publish_skipped", 10}};
  const std::string text = format_pipeline_stats(s);
  EXPECT_NE(text.find("publish (end to end)"), std::string::npos);
  EXPECT_NE(text.find("publish_skipped=10"), std::string::npos);
  const std::string json = pipeline_stats_json(s);
  EXPECT_NE(json.find("\"frames\": 190"), std::string::npos);
  EXPECT_NE(json.find("\"publish\": {\"count\": 190, \"p50_us\": 4000.0, \"p99_us\": 5000.0, "
                      "\"p999_us\": 5500.0, \"max_us\": 6000.0"),
            std::string::npos)
      << json;
  EXPECT_NE(text.find("p99.9"), std::string::npos);
  EXPECT_NE(json.find("\"publish_skipped\": 10"), std::string::npos);
}

}  // namespace
}  // namespace mocap::pipeline
