// Faults around the live pipeline (functional, never speed):
//   * nobody listens on the UDP port (the consumer was killed): every frame is still
//     processed and published, any send error is only counted;
//   * one camera stalls for >= 300 ms: the other camera's frames keep being dequeued
//     (capture does not wait on the stalled one), the stall shows in the stats
//     (camera_max_silence_us_cam1, dequeue_timeouts_cam1) and in health() while it
//     lasts, and the tracker publishes again afterwards;
//   * free-running cameras with independent sequence counters pair by timestamp
//     (PairBy::kTimestamp) and not by sequence;
//   * camera 0's clock steps 5 s ahead and back, then back and ahead (hal::FaultCamera),
//     and two of its images are full of blobs: every frame is still processed, the steps
//     are counted per camera (timestamp_backwards/jumps), the identifier drops its prior
//     on the steps back (identify_bad_timestamps), and the detector, stereo and
//     identification counters reach the stats and health() unchanged.
// Every fault comes from the one fault-injecting camera, hal::FaultCamera (kStall,
// kSequenceOffset, kTimestampJump, kReplaceImage).
#include <gtest/gtest.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <thread>

#include "hal/fault_camera.h"
#include "pipeline/publish/udp_publisher.h"
#include "pipeline/stats_report.h"
#include "tests/pipeline/pipeline_fixture.h"
#include "tests/support/udp_port.h"

namespace mocap::pipeline {
namespace {

using test::counter;
using test::RecordingSink;
using test::SimRigFixture;

TEST(PipelineFaults, NoUdpReceiverIsCountedNotFatal) {
  auto udp =
      publish::UdpPublisher::create({"127.0.0.1:" + std::to_string(mocap::test::free_udp_port())});
  ASSERT_TRUE(udp.ok()) << udp.error().message;
  test::UdpPublisherSink udp_sink(std::move(udp).value());
  RecordingSink record(200);
  SimRigFixture rig;
  PipelineOptions opt = test::test_options();
  opt.max_frames = 60;
  opt.pacing = TriggerPacing::kLockstep;  // lossless: every frame reaches the sinks
  auto p = Pipeline::create(rig.processor(), rig.cameras(), {&udp_sink, &record}, opt);
  ASSERT_TRUE(p.ok());
  ASSERT_TRUE((*p)->start().ok());
  test::wait_finished(**p);
  (*p)->stop();
  const PipelineStats st = (*p)->stats();
  EXPECT_EQ(st.published, 60u) << format_pipeline_stats(st);
  EXPECT_EQ(record.count(), 60u);
  const publish::UdpPublisherCounters& c = udp_sink.publisher().counters();
  EXPECT_EQ(c.messages, 60u);
  // The connected socket reports each datagram's ICMP port unreachable on the next
  // sendto() (ECONNREFUSED), which the publisher repeats: every datagram is sent, and
  // "no listener" is not a sink failure.
  EXPECT_EQ(c.datagrams_sent, 60u);
  EXPECT_GT(c.no_listener, 0u);
  EXPECT_EQ(c.refused + c.would_block + c.other_errors, 0u);
  EXPECT_EQ(counter(st, "sink_failures"), 0u);
  // Each sink's publish time has a histogram of its own (one sample per frame).
  for (const char* name : {"sink_work_udp", "sink_work_recording"}) {
    const auto it = std::find_if(st.latency.begin(), st.latency.end(),
                                 [&](const auto& l) { return l.first == name; });
    ASSERT_NE(it, st.latency.end()) << name;
    EXPECT_EQ(it->second.count, 60u) << name;
  }
}

TEST(PipelineFaults, StalledCameraIsReportedAndDoesNotBlockTheOther) {
  SimRigFixture rig(7);
  // After 40 frames, camera 1 stays silent for 60 dequeue calls: one per 5 ms trigger
  // period (each waits until the next trigger), so at least 300 ms.
  auto cam1 = hal::FaultCamera::wrap(*rig.cams[1], {{hal::Fault::kStall, 40, 60, 0}});
  ASSERT_TRUE(cam1.ok()) << cam1.error().message;
  RecordingSink record(400);
  PipelineOptions opt = test::test_options();
  opt.max_frames = 160;
  opt.trigger_rate_hz = 200.0;
  auto p = Pipeline::create(rig.processor(), {rig.cams[0].get(), cam1->get()}, {&record}, opt);
  ASSERT_TRUE(p.ok());
  ASSERT_TRUE((*p)->start().ok());
  std::int64_t max_silent_ms = 0;
  const auto until = std::chrono::steady_clock::now() + std::chrono::seconds(20);
  while (!(*p)->finished() && std::chrono::steady_clock::now() < until) {
    max_silent_ms = std::max(max_silent_ms, (*p)->health().camera_silent_ms[1]);
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
  (*p)->stop();
  const PipelineStats st = (*p)->stats();
  const std::string report = format_pipeline_stats(st);
  EXPECT_EQ(st.triggered, 160u);
  // Camera 0 was served throughout: every one of its frames was dequeued.
  EXPECT_EQ(rig.cams[0]->counters().frames.get(), 160u) << report;
  // The stall is visible while it lasts and in the statistics afterwards.
  EXPECT_GE(max_silent_ms, 150) << report;
  EXPECT_GE(counter(st, "camera_max_silence_us_cam1"), 250'000u) << report;
  EXPECT_GT(counter(st, "dequeue_timeouts_cam1"), 0u) << report;
  EXPECT_LT(counter(st, "camera_max_silence_us_cam0"), counter(st, "camera_max_silence_us_cam1"));
  // Frames of the stall were lost, the tracker published again after it (after frame
  // 40 + 60 stalled dequeues; how many of the last frames a loaded machine drops, e.g.
  // under TSan, is not the point: they are counted), and the run ended with every frame
  // published or counted as lost (the last set too: a frame that came late is taken).
  EXPECT_GT(counter(st, "frames_dropped"), 0u) << report;
  EXPECT_TRUE((*p)->finished()) << report;
  ASSERT_GT(record.count(), 0u);
  EXPECT_GT(record[record.count() - 1].sequence, 100u) << report;
  EXPECT_EQ(st.triggered, st.published + counter(st, "frames_dropped")) << report;
}

// The run's end: the last trigger's frame of camera 1 comes after its dequeue pass (late,
// by three empty dequeues), or never. Either way the run finishes on its own; the late
// frame completes the last set, the missing one is counted as lost.
struct TailRun {
  PipelineStats st;
  bool finished = false;
  std::uint64_t last_sequence = 0;
  std::size_t published = 0;
};

TailRun run_with_last_frame_stalled(std::uint64_t stall_calls) {
  TailRun out;
  SimRigFixture rig(7);
  constexpr std::uint64_t kFrames = 30;
  auto cam1 =
      hal::FaultCamera::wrap(*rig.cams[1], {{hal::Fault::kStall, kFrames - 1, stall_calls, 0}});
  EXPECT_TRUE(cam1.ok()) << cam1.error().message;
  if (!cam1.ok()) return out;
  RecordingSink record(100);
  PipelineOptions opt = test::test_options();
  opt.max_frames = kFrames;
  opt.trigger_rate_hz = 100.0;
  auto p = Pipeline::create(rig.processor(), {rig.cams[0].get(), cam1->get()}, {&record}, opt);
  EXPECT_TRUE(p.ok());
  if (!p.ok()) return out;
  EXPECT_TRUE((*p)->start().ok());
  test::wait_finished(**p, 20.0);
  out.finished = (*p)->finished();
  (*p)->stop();
  out.st = (*p)->stats();
  out.published = record.count();
  if (record.count() > 0) out.last_sequence = record[record.count() - 1].sequence;
  return out;
}

TEST(PipelineFaults, TheLastTriggersLateFrameCompletesItsSetAndTheRunEnds) {
  const TailRun r = run_with_last_frame_stalled(3);
  const std::string report = format_pipeline_stats(r.st);
  EXPECT_TRUE(r.finished) << report;
  EXPECT_EQ(r.st.triggered, 30u);
  EXPECT_EQ(r.st.triggered, r.st.published + counter(r.st, "frames_dropped")) << report;
  // On an idle machine every frame; a loaded one may drop some at a full ring (counted),
  // but never the late one, which only waited in its camera.
  EXPECT_EQ(r.last_sequence, 29u) << report;
  EXPECT_EQ(counter(r.st, "capture_dropped_cam1") > 0 ? 0u : counter(r.st, "pair_unmatched_cam0"),
            0u)
      << report;
}

TEST(PipelineFaults, TheLastTriggersFrameThatNeverComesIsCountedAndTheRunEnds) {
  const TailRun r = run_with_last_frame_stalled(hal::FaultRule::kForever);
  const std::string report = format_pipeline_stats(r.st);
  EXPECT_TRUE(r.finished) << report;
  EXPECT_EQ(r.st.triggered, 30u);
  EXPECT_EQ(r.st.triggered, r.st.published + counter(r.st, "frames_dropped")) << report;
  EXPECT_GE(counter(r.st, "frames_dropped"), 1u) << report;
  EXPECT_GE(counter(r.st, "pair_unmatched_cam0"), 1u) << "camera 0's last frame" << report;
  EXPECT_LT(r.last_sequence, 29u) << report;
  EXPECT_GT(r.published, 0u) << report;
}

TEST(PipelineFaults, FreeRunningCamerasPairByTimestamp) {
  {
    SimRigFixture rig;
    RecordingSink record(1);
    PipelineOptions opt = test::test_options();
    opt.pair_by = PairBy::kTimestamp;
    opt.pair_tolerance_us = 0;
    auto p = Pipeline::create(rig.processor(), rig.cameras(), {&record}, opt);
    ASSERT_FALSE(p.ok());
    EXPECT_NE(p.error().message.find("pair_tolerance_us"), std::string::npos);
  }
  for (const PairBy mode : {PairBy::kTimestamp, PairBy::kSequence}) {
    SimRigFixture rig;
    // Independent frame counters: camera 1's sequence numbers never match camera 0's.
    auto cam1 = hal::FaultCamera::wrap(
        *rig.cams[1], {{hal::Fault::kSequenceOffset, 0, hal::FaultRule::kForever, 1000}});
    ASSERT_TRUE(cam1.ok()) << cam1.error().message;
    for (hal::Camera* c : {static_cast<hal::Camera*>(rig.cams[0].get()),
                           static_cast<hal::Camera*>(rig.cams[1].get())}) {
      hal::CameraConfig cfg = c->config();
      cfg.trigger = hal::TriggerMode::kFreeRun;
      cfg.frame_rate_hz = 100.0;
      ASSERT_TRUE(c->configure(cfg).ok());
    }
    RecordingSink record(400);
    PipelineOptions opt = test::test_options();
    opt.pair_by = mode;
    opt.pair_tolerance_us = 2000;  // the cameras start within microseconds of each other
    auto p = Pipeline::create(rig.processor(), {rig.cams[0].get(), cam1->get()}, {&record}, opt);
    ASSERT_TRUE(p.ok()) << p.error().message;
    ASSERT_TRUE((*p)->start().ok());
    std::this_thread::sleep_for(std::chrono::milliseconds(400));
    (*p)->stop();
    const PipelineStats st = (*p)->stats();
    if (mode == PairBy::kSequence) {
      EXPECT_EQ(st.published, 0u) << format_pipeline_stats(st);
      continue;
    }
    EXPECT_GE(st.published, 10u) << format_pipeline_stats(st);
    std::size_t all_found = 0;
    for (std::size_t i = 0; i < record.count(); ++i) {
      if (i > 0) {
        EXPECT_GT(record[i].sequence, record[i - 1].sequence);
      }
      all_found += (record[i].flags & client::kFlagAllBodiesFound) != 0;
    }
    // Both cameras run on the same frame grid (offset by microseconds): pairing by
    // timestamp matched them one to one (nothing unmatched) and the stereo
    // reconstruction finds the rig (the scene's loop frames 2..17 are fully visible).
    // (a frame a loaded machine made a detector skip leaves its partner unmatched)
    const std::uint64_t lost_before_pairing =
        counter(st, "detect0_skipped") + counter(st, "detect1_skipped") +
        counter(st, "detect0_no_slot") + counter(st, "detect1_no_slot") +
        counter(st, "capture_dropped_cam0") + counter(st, "capture_dropped_cam1");
    EXPECT_LE(counter(st, "pair_unmatched_cam0") + counter(st, "pair_unmatched_cam1"),
              lost_before_pairing + 2)
        << format_pipeline_stats(st);
    EXPECT_GE(all_found, 5u) << format_pipeline_stats(st);
  }
}

// Every mirrored counter equals the library's own after stop() (the mirror is the last
// frame's state, published by the stage thread that owns the library).
template <class Source, std::size_t N>
void expect_mirrored(const PipelineStats& st, const std::string& prefix,
                     const std::array<CounterField<Source>, N>& fields, const Source& source) {
  for (const CounterField<Source>& f : fields)
    EXPECT_EQ(counter(st, prefix + f.name), f.read(source)) << prefix << f.name;
}

TEST(PipelineFaults, ClockStepsAndLibraryCountersAreReported) {
  SimRigFixture rig(6, test::render_loop(6));  // 6 frames (0..5..0) render in half the time
  const hal::CameraConfig cfg = rig.cams[0]->config();
  Image storm(cfg.width, cfg.height, cfg.format, 255);  // 2x2 dots every 5 px: overflows
  for (int y = 0; y < cfg.height; ++y) {
    for (int x = 0; x < cfg.width; ++x) storm.row8(y)[x] = (x % 5 < 2 && y % 5 < 2) ? 240 : 10;
  }
  const std::int64_t step_ns = 5'000'000'000;
  auto cam0 = hal::FaultCamera::wrap(*rig.cams[0],
                                     {{hal::Fault::kTimestampJump, 10, 5, step_ns},
                                      {hal::Fault::kTimestampJump, 20, 5, -step_ns},
                                      {hal::Fault::kReplaceImage, 30, 2, 0}},
                                     &storm);
  ASSERT_TRUE(cam0.ok()) << cam0.error().message;
  constexpr std::uint64_t kFrames = 36;
  RecordingSink record(kFrames);
  PipelineOptions opt = test::test_options();
  opt.max_frames = kFrames;
  opt.pacing = TriggerPacing::kLockstep;  // lossless: every frame reaches identification
  auto p = Pipeline::create(rig.processor(), {cam0->get(), rig.cams[1].get()}, {&record}, opt);
  ASSERT_TRUE(p.ok()) << p.error().message;
  ASSERT_TRUE((*p)->start().ok());
  test::wait_finished(**p, 20.0);
  (*p)->stop();
  const PipelineStats st = (*p)->stats();
  const PipelineHealth h = (*p)->health();
  const std::string report = format_pipeline_stats(st);
  ASSERT_EQ(st.published, kFrames) << report;
  ASSERT_EQ(record.count(), kFrames);

  // The stepped frames were processed and carry the camera's timestamps unchanged.
  for (std::size_t i = 1; i < kFrames; ++i) {
    const std::int64_t dt = record[i].capture_ns - record[i - 1].capture_ns;
    const bool step_ahead = i == 10 || i == 25, step_back = i == 15 || i == 20;
    EXPECT_EQ(dt > step_ns / 2, step_ahead) << "frame " << i;
    EXPECT_EQ(dt < -step_ns / 2, step_back) << "frame " << i;
  }
  // Ahead at 10 and 25 (back to the true time), back at 15 and 20; camera 1 is clean.
  EXPECT_EQ(counter(st, "timestamp_jumps_cam0"), 2u) << report;
  EXPECT_EQ(counter(st, "timestamp_backwards_cam0"), 2u) << report;
  EXPECT_EQ(counter(st, "timestamp_jumps_cam1"), 0u) << report;
  EXPECT_EQ(counter(st, "timestamp_backwards_cam1"), 0u) << report;
  EXPECT_EQ(h.timestamp_steps[0], 4u);
  EXPECT_EQ(h.timestamp_steps[1], 0u);
  const std::string line = format_progress_line(1.0, 1.0, LatencyStats{}, h);
  EXPECT_NE(line.find(" clock steps=4/0"), std::string::npos) << line;
  // The identifier saw the two steps back (camera 0's time is the frame's time) and
  // dropped its prior there instead of predicting across them; tracking resumed.
  const IdentifyCounters& ic = (*p)->processor().identify_counters();
  EXPECT_GE(ic.bad_timestamps, 1u) << report;
  EXPECT_LE(ic.bad_timestamps, 2u) << report;
  bool resumed = false;
  for (std::size_t i = 26; i < kFrames; ++i) {
    for (std::uint16_t j = 0; j < record[i].joint_count; ++j)
      resumed = resumed || record[i].joints[j].valid != 0;
  }
  EXPECT_TRUE(resumed) << "a valid joint angle after the last step";

  // The library counters: the storm overflowed camera 0's detector only.
  EXPECT_GE(counter(st, "detect_cam0_frames_overflow"), 1u) << report;
  EXPECT_EQ(counter(st, "detect_cam1_frames_overflow"), 0u) << report;
  EXPECT_EQ(h.detect_overflow_frames[0], counter(st, "detect_cam0_frames_overflow"));
  EXPECT_EQ(counter(st, "detect_cam0_frames"), kFrames);
  EXPECT_GT(counter(st, "detect_cam1_blobs"), kFrames);  // several markers per frame
  EXPECT_EQ(counter(st, "stereo_frames"), kFrames);
  EXPECT_EQ(counter(st, "identify_frames"), kFrames);
  const FrameProcessor& fp = (*p)->processor();
  expect_mirrored(st, "detect_cam0_", kDetectorFields, fp.detector_counters(0));
  expect_mirrored(st, "detect_cam1_", kDetectorFields, fp.detector_counters(1));
  expect_mirrored(st, "stereo_", kStereoFields, fp.stereo_counters());
  expect_mirrored(st, "identify_", kIdentifyFields, fp.identify_counters());
  // ... and the JSON of --stats.
  const std::string json = pipeline_stats_json(st);
  EXPECT_NE(json.find("\"timestamp_jumps_cam0\": 2"), std::string::npos) << json;
  EXPECT_NE(json.find("\"identify_bad_timestamps\": "), std::string::npos);
}

}  // namespace
}  // namespace mocap::pipeline
