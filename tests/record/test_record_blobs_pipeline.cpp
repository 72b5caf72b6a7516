// Design: `mocap record --blobs` keeps every frame in order behind a stall. The recorder
// is attached to the live pipeline as the command attaches it (FrameRecorder::attach:
// blob tap and PipelineOptions::every_frame) on the simulated stereo pair, 100 frames at
// 100 Hz, and the identify stage stalls 35 ms on every 10th frame (an observer on its
// thread: a hard frame). With the command's options no stage skips a frame for a newer
// one (detect#_skipped, identify_skipped, publish_skipped all 0): identify and publish
// (a sink in the place of the outputs) see every frame in sequence order, and the
// recording holds every detected blob list; a frame is missing only where a full ring
// dropped it, counted. The control run with newest-first stages (every_frame off,
// catch_up_ns 0) skips frames behind the same stall: the stall is real, and the check can fail.
// Counts, never timing: the same under load and TSan.
#include <gtest/gtest.h>

#include <array>
#include <chrono>
#include <string>
#include <thread>

#include "pipeline/record/frame_recorder.h"
#include "pipeline/stats_report.h"
#include "tests/pipeline/pipeline_fixture.h"
#include "tests/support/test_support.h"

namespace mocap::record {
namespace {

using pipeline::test::counter;

constexpr std::uint64_t kStalledRunFrames = 100;

// On the identify thread: the sequences identify processed, in its order; stalls 35 ms on
// every 10th frame (3.5 frame periods). Read after the pipeline stopped (joined).
class StallingObserver final : public pipeline::FrameObserver {
 public:
  void observe(std::uint64_t sequence, std::int64_t, const FrameOutput&) noexcept override {
    if (count % 10 == 0) std::this_thread::sleep_for(std::chrono::milliseconds(35));
    if (count < sequences.size()) sequences[count] = sequence;
    ++count;
  }
  std::array<std::uint64_t, 256> sequences{};
  std::size_t count = 0;
};

struct BlobRecordingRun {
  StallingObserver observer;
  pipeline::test::RecordingSink sink{1000};
  pipeline::PipelineStats stats;
  RecorderCounts counts;
};

// `mocap record --blobs` of kStalledRunFrames frames; `newest`: the control, every_frame
// turned off after the recorder was attached and the newest frame first (no catch-up).
void record_blobs(bool newest, BlobRecordingRun& run) {
  pipeline::test::SimRigFixture rig;
  test::TempDir dir("rec_blobs_pipeline");
  RecorderOptions ro;
  ro.dir = dir.path();
  for (std::size_t c = 0; c < rig.cams.size(); ++c) {
    const hal::CameraConfig cc = rig.cams[c]->native_config();
    ro.camera_names.push_back(rig.loop->scene().rig.cameras[c].name);
    ro.cameras.push_back(CameraGeometry{cc.width, cc.height, cc.format});
  }
  ro.max_frames = kStalledRunFrames;
  ro.blobs = true;
  auto rec = FrameRecorder::create(ro);
  ASSERT_TRUE(rec) << rec.error().message;
  pipeline::PipelineOptions opt = pipeline::test::test_options();
  opt.max_frames = kStalledRunFrames;
  opt.trigger_rate_hz = 100.0;
  (*rec)->attach(opt);
  if (newest) {
    opt.every_frame = false;
    opt.catch_up_ns = 0;
  }
  opt.observer = &run.observer;
  auto p = pipeline::Pipeline::create(rig.processor(), rig.cameras(), {&run.sink}, opt);
  ASSERT_TRUE(p.ok()) << p.error().message;
  (*rec)->start();
  ASSERT_TRUE((*p)->start().ok());
  pipeline::test::wait_finished(**p);
  (*p)->stop();
  ASSERT_TRUE((*rec)->finish());
  run.stats = (*p)->stats();
  run.counts = (*rec)->counts();
}

TEST(RecordBlobsPipeline, IdentifyAndPublishTakeEveryFrameInOrderBehindAStall) {
  BlobRecordingRun newest;
  record_blobs(true, newest);
  const pipeline::PipelineStats& n = newest.stats;
  EXPECT_GT(counter(n, "identify_skipped") + counter(n, "publish_skipped"), 0u)
      << "the control did not skip: the stall does not test anything\n"
      << pipeline::format_pipeline_stats(n);

  BlobRecordingRun run;
  record_blobs(false, run);
  const pipeline::PipelineStats& st = run.stats;
  const std::string stats = pipeline::format_pipeline_stats(st);
  EXPECT_EQ(st.triggered, kStalledRunFrames);
  EXPECT_EQ(counter(st, "detect0_skipped") + counter(st, "detect1_skipped"), 0u) << stats;
  EXPECT_EQ(counter(st, "identify_skipped"), 0u) << stats;
  EXPECT_EQ(counter(st, "publish_skipped"), 0u) << stats;
  // What a full ring dropped (a loaded test machine), before the tap and before identify.
  const std::uint64_t before_tap = counter(st, "capture_dropped_cam0") +
                                   counter(st, "capture_dropped_cam1") +
                                   counter(st, "detect0_no_slot") + counter(st, "detect1_no_slot");
  // A set that lost a frame there never paired: counted once, in frames_unpaired.
  const std::uint64_t unpaired = counter(st, "frames_unpaired");
  EXPECT_LE(unpaired,
            before_tap + counter(st, "pair_overflow_cam0") + counter(st, "pair_overflow_cam1"))
      << stats;
  // The recording: every detected blob list of both cameras, none dropped at the tap.
  EXPECT_EQ(run.counts.blob_lists_written + before_tap, 2 * kStalledRunFrames) << stats;
  EXPECT_EQ(run.counts.dropped[0] + run.counts.dropped[1], 0u);
  // Identify: every frame, in order.
  EXPECT_EQ(run.observer.count + unpaired, kStalledRunFrames) << stats;
  for (std::size_t i = 1; i < run.observer.count && i < run.observer.sequences.size(); ++i)
    EXPECT_GT(run.observer.sequences[i], run.observer.sequences[i - 1]) << i;
  // Publish: every frame identify handed on, in order.
  EXPECT_EQ(run.sink.count() + counter(st, "identify_no_slot"), run.observer.count) << stats;
  for (std::size_t i = 1; i < run.sink.count(); ++i)
    EXPECT_GT(run.sink[i].sequence, run.sink[i - 1].sequence) << i;
}

}  // namespace
}  // namespace mocap::record
