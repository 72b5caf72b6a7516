// Fault injection through the HAL (issue 8): the live pipeline on the simulated stereo
// pair with one camera wrapped by hal::FaultCamera. For each fault (I/O errors, corrupt
// frames, a camera that stops and resumes, partial frames, duplicated and out-of-order
// sequence numbers, clock steps, an image full of blobs) the tracker must keep
// processing the frames it can, show the fault in its counters, never publish a
// sequence number twice or backwards, and resume on its own: once the fault is over,
// messages with every body found flow again. (A dead UDP consumer, RouDi stopping and a
// stalled detector are covered by the pipeline's own tests.)
#include <gtest/gtest.h>

#include <memory>
#include <vector>

#include "hal/fault_camera.h"
#include "tests/pipeline/pipeline_fixture.h"
#include "tests/support/alloc_counter.h"

namespace mocap::pipeline::test {
namespace {

using hal::Fault;
using hal::FaultRule;

constexpr std::uint64_t kFrames = 60;

// A short pre-rendered loop (6 frames, ping-pong: 0..5..0) so that each test, which
// ctest runs in its own process, renders in ~0.3 s instead of the pipeline fixture's 30.
std::shared_ptr<const hal::SimFrameLoop> short_loop() {
  static std::shared_ptr<const hal::SimFrameLoop> loop = [] {
    sim::SimOptions o;
    o.frames = 6;
    auto l = hal::SimFrameLoop::render(o);
    EXPECT_TRUE(l.ok()) << (l.ok() ? "" : l.error().message);
    return l.ok() ? *l : nullptr;
  }();
  return loop;
}

// The simulated stereo pair on the short loop and a processor with the true model.
struct ShortRig {
  std::shared_ptr<hal::SimTrigger> trigger = std::make_shared<hal::SimTrigger>(short_loop());
  std::unique_ptr<hal::SimCamera> cams[2];
  ShortRig() {
    for (int c = 0; c < 2; ++c) {
      auto cam = hal::SimCamera::open(trigger, c);
      EXPECT_TRUE(cam.ok());
      cams[c] = std::move(cam).value();
      hal::CameraConfig cfg = cams[c]->native_config();
      cfg.buffer_count = 6;
      EXPECT_TRUE(cams[c]->configure(cfg).ok());
    }
  }
  std::vector<hal::Camera*> cameras() { return {cams[0].get(), cams[1].get()}; }
  FrameProcessor processor() const {
    const sim::SimScene& sc = short_loop()->scene();
    auto p = FrameProcessor::create(sc.rig, sc.targets, &sc.joints_true, TrackerConfig{});
    EXPECT_TRUE(p.ok()) << (p.ok() ? "" : p.error().message);
    return std::move(p).value();
  }
};

struct FaultRun {
  PipelineStats stats;
  std::vector<client::JointsMessage> messages;
  detect::DetectorCounters detector[2];
  std::uint64_t injected = 0;
};

FaultRun run_with_faults(int camera, const std::vector<FaultRule>& rules,
                         const Image* substitute = nullptr, std::uint64_t frames = kFrames) {
  FaultRun run;
  ShortRig rig;
  auto fault = hal::FaultCamera::wrap(*rig.cams[camera], rules, substitute);
  EXPECT_TRUE(fault.ok()) << (fault.ok() ? "" : fault.error().message);
  if (!fault.ok()) return run;
  std::vector<hal::Camera*> cams = rig.cameras();
  cams[static_cast<std::size_t>(camera)] = fault->get();
  RecordingSink sink(frames + 8);
  PipelineOptions opt = test_options();
  opt.max_frames = frames;
  auto p = Pipeline::create(rig.processor(), cams, {&sink}, opt);
  EXPECT_TRUE(p.ok()) << (p.ok() ? "" : p.error().message);
  if (!p.ok()) return run;
  auto started = (*p)->start();
  EXPECT_TRUE(started.ok()) << (started.ok() ? "" : started.error().message);
  wait_finished(**p, 10.0);
  (*p)->stop();
  run.stats = (*p)->stats();
  for (std::size_t i = 0; i < sink.count(); ++i) run.messages.push_back(sink[i]);
  for (int c = 0; c < 2; ++c) run.detector[c] = (*p)->processor().detector_counters(c);
  run.injected = (*fault)->injected_total();
  return run;
}

// Sequence numbers strictly increase (a consumer never sees a duplicate or a step back).
void expect_strictly_increasing(const FaultRun& r) {
  for (std::size_t i = 1; i < r.messages.size(); ++i) {
    EXPECT_GT(r.messages[i].sequence, r.messages[i - 1].sequence) << "message " << i;
  }
}

// Resumed: a message after the fault window with a valid joint angle (both bodies of
// a joint identified again).
bool resumed_after(const FaultRun& r, std::uint64_t sequence) {
  for (const auto& m : r.messages) {
    if (m.sequence <= sequence) continue;
    for (std::uint16_t j = 0; j < m.joint_count; ++j)
      if (m.joints[j].valid != 0) return true;
  }
  return false;
}

bool published(const FaultRun& r, std::uint64_t sequence) {
  for (const auto& m : r.messages)
    if (m.sequence == sequence) return true;
  return false;
}

std::uint64_t dropped_by_pairing(const FaultRun& r, int camera) {
  return counter(r.stats, "pair_unmatched_cam" + std::to_string(camera)) +
         counter(r.stats, "pair_overflow_cam" + std::to_string(camera));
}

TEST(Faults, IoErrorsAreCountedAndTrackingResumes) {
  const FaultRun r = run_with_faults(0, {{Fault::kIoError, 10, 5, 0}});
  EXPECT_EQ(r.injected, 5u);
  EXPECT_EQ(counter(r.stats, "dequeue_errors"), 5u);
  EXPECT_GE(dropped_by_pairing(r, 1), 1u) << "camera 1's partners of the lost frames are dropped";
  for (std::uint64_t s = 10; s < 15; ++s) EXPECT_FALSE(published(r, s)) << s;
  EXPECT_TRUE(resumed_after(r, 15));
  expect_strictly_increasing(r);
}

TEST(Faults, CorruptFramesAreCountedAndTrackingResumes) {
  const FaultRun r =
      run_with_faults(1, {{Fault::kCorruptFrame, 5, 3, 0}, {Fault::kCorruptFrame, 30, 1, 0}});
  EXPECT_EQ(r.injected, 4u);
  EXPECT_EQ(counter(r.stats, "dequeue_errors"), 4u);
  EXPECT_TRUE(resumed_after(r, 31));
  expect_strictly_increasing(r);
}

TEST(Faults, CameraThatStopsResumesOnItsOwn) {
  // Camera 1 delivers nothing for 25 frames (each dequeue waits its whole timeout).
  const FaultRun r = run_with_faults(1, {{Fault::kTimeout, 10, 25, 0}}, nullptr, 70);
  EXPECT_EQ(r.injected, 25u);
  EXPECT_GE(counter(r.stats, "dequeue_timeouts_cam1"), 25u);
  EXPECT_EQ(counter(r.stats, "dequeue_timeouts_cam0"), 0u);
  // The silence is reported: 25 frames at 100 Hz without a frame from camera 1.
  EXPECT_GE(counter(r.stats, "camera_max_silence_us_cam1"), 200'000u);
  EXPECT_GE(dropped_by_pairing(r, 0), 1u) << "camera 0's frames without a partner are dropped";
  for (std::uint64_t s = 10; s < 35; ++s) EXPECT_FALSE(published(r, s)) << s;
  EXPECT_TRUE(resumed_after(r, 35));
  expect_strictly_increasing(r);
}

TEST(Faults, PartialFramesAreRefusedByTheDetector) {
  const FaultRun r = run_with_faults(
      0, {{Fault::kTruncatedFrame, 10, 3, 200}, {Fault::kTruncatedFrame, 20, 2, 0}});
  EXPECT_EQ(r.injected, 5u);
  // 200-row frames reach the detector and are refused (wrong size); 0-row frames are
  // empty and count as absent.
  EXPECT_GE(r.detector[0].frames_invalid, 1u);
  EXPECT_LE(r.detector[0].frames_invalid, 3u);
  for (const auto& m : r.messages) {
    if ((m.sequence >= 10 && m.sequence < 13) || (m.sequence >= 20 && m.sequence < 22)) {
      EXPECT_EQ(m.flags & client::kFlagAllBodiesFound, 0u)
          << "no bodies from one camera, sequence " << m.sequence;
    }
  }
  EXPECT_TRUE(resumed_after(r, 22));
  expect_strictly_increasing(r);
}

TEST(Faults, DuplicatedSequenceNumbersAreNotPublishedTwice) {
  const FaultRun r = run_with_faults(
      0, {{Fault::kDuplicateSequence, 10, 3, 0}, {Fault::kDuplicateSequence, 30, 1, 0}});
  EXPECT_EQ(r.injected, 4u);
  EXPECT_GE(dropped_by_pairing(r, 0) + dropped_by_pairing(r, 1), 3u);
  EXPECT_TRUE(resumed_after(r, 31));
  expect_strictly_increasing(r);
}

TEST(Faults, OutOfOrderSequenceNumbersAreNotPublishedBackwards) {
  const FaultRun r =
      run_with_faults(1, {{Fault::kSwapOrder, 10, 1, 0}, {Fault::kSwapOrder, 25, 1, 0}});
  EXPECT_EQ(r.injected, 2u);
  EXPECT_GE(dropped_by_pairing(r, 0) + dropped_by_pairing(r, 1), 1u);
  EXPECT_TRUE(resumed_after(r, 27));
  expect_strictly_increasing(r);
}

TEST(Faults, ClockStepsDoNotStopTracking) {
  // Camera 0's timestamps (the message's capture time) step 5 s ahead, then 5 s back.
  const std::int64_t step_ns = 5'000'000'000;
  const FaultRun r = run_with_faults(
      0, {{Fault::kTimestampJump, 10, 5, step_ns}, {Fault::kTimestampJump, 20, 5, -step_ns}});
  EXPECT_EQ(r.injected, 10u);
  bool saw_step = false;
  for (std::size_t i = 1; i < r.messages.size(); ++i) {
    if (r.messages[i].capture_ns - r.messages[i - 1].capture_ns > step_ns / 2) saw_step = true;
  }
  EXPECT_TRUE(saw_step) << "the capture time passes through as the camera reported it";
  EXPECT_GE(r.stats.published, kFrames / 2);
  EXPECT_TRUE(resumed_after(r, 25));
  expect_strictly_increasing(r);
}

TEST(Faults, ImageFullOfBlobsOverflowsTheDetectorWithoutOverrun) {
  ShortRig probe;  // the camera's size and format
  const hal::CameraConfig cfg = probe.cams[0]->config();
  Image storm(cfg.width, cfg.height, cfg.format, 255);
  // 2x2 dots every 5 pixels: ~32000 blobs (period 5, not a power of two, so the
  // detector's sparse background sample still sees mostly background).
  for (int y = 0; y < cfg.height; ++y) {
    for (int x = 0; x < cfg.width; ++x) storm.row8(y)[x] = (x % 5 < 2 && y % 5 < 2) ? 240 : 10;
  }
  const FaultRun r = run_with_faults(0, {{Fault::kReplaceImage, 10, 5, 0}}, &storm);
  EXPECT_EQ(r.injected, 5u);
  EXPECT_GE(r.detector[0].frames_overflow, 1u);
  EXPECT_GT(r.detector[0].blobs_dropped + r.detector[0].runs_overflow, 0u);
  EXPECT_EQ(r.detector[1].frames_overflow, 0u);
  EXPECT_TRUE(resumed_after(r, 15));
  expect_strictly_increasing(r);
}

TEST(Faults, InjectionIsAllocationFreeAndReleasesEveryBuffer) {
  ShortRig rig;
  auto cam = hal::FaultCamera::wrap(*rig.cams[0], {{Fault::kIoError, 2, 2, 0},
                                                   {Fault::kTruncatedFrame, 5, 1, 10},
                                                   {Fault::kDuplicateSequence, 7, 1, 0},
                                                   {Fault::kSwapOrder, 9, 1, 0},
                                                   {Fault::kTimestampJump, 12, 3, -1000},
                                                   {Fault::kTimeout, 16, 1, 0}});
  ASSERT_TRUE(cam.ok());
  ASSERT_TRUE((*cam)->start().ok());
  int ok = 0, failed = 0;
  const mocap::test::AllocationScope allocs;
  for (int i = 0; i < 40; ++i) {  // camera 0 is the trigger master: one frame per trigger
    ASSERT_EQ((*cam)->trigger(), hal::CameraStatus::kOk);
    hal::Frame f;
    if ((*cam)->dequeue(f, 1) != hal::CameraStatus::kOk) {
      ++failed;
      continue;
    }
    ++ok;
    EXPECT_EQ((*cam)->release(f), hal::CameraStatus::kOk);
  }
  EXPECT_EQ(allocs.count(), 0u);
  EXPECT_EQ(failed, 3);  // two I/O errors and one timeout; every lost frame was released
  EXPECT_EQ(ok, 37);
  EXPECT_EQ((*cam)->injected_total(), 9u);
  EXPECT_EQ((*cam)->frames_seen(), 40u);
  (*cam)->stop();
}

TEST(Faults, WrapperValidatesItsSchedule) {
  ShortRig rig;
  EXPECT_FALSE(hal::FaultCamera::wrap(*rig.cams[0], {{Fault::kIoError, 0, 0, 0}}).ok());
  EXPECT_FALSE(hal::FaultCamera::wrap(*rig.cams[0], {{Fault::kReplaceImage, 0, 1, 0}}).ok());
  EXPECT_FALSE(hal::FaultCamera::wrap(*rig.cams[0], std::vector<FaultRule>(17)).ok());
  Image wrong(8, 8, PixelFormat::kMono8, 255);
  auto cam = hal::FaultCamera::wrap(*rig.cams[0], {{Fault::kReplaceImage, 0, 1, 0}}, &wrong);
  ASSERT_TRUE(cam.ok());
  EXPECT_FALSE((*cam)->start().ok()) << "a substitute of the wrong size is refused at start";
}

}  // namespace
}  // namespace mocap::pipeline::test
