// The replay backend on a small recording written by the test: every frame in order
// with its number and timestamp, a missing file delivered as a missing frame (not a
// stop), malformed files counted, end of stream, recorded timing honoured (a lower
// bound: frames never come early), the recorded timestamp kept and the delivery stamped
// (the latencies' origin), software trigger, seek (a node's central-triggered replay),
// buffer exhaustion, and no heap allocation per frame.
#include <gtest/gtest.h>

#include <memory>
#include <utility>

#include "formats/pgm.h"
#include "formats/rig_yaml.h"
#include "hal/replay_camera.h"
#include "tests/support/alloc_counter.h"
#include "tests/support/test_support.h"

namespace mocap::hal {
namespace {

constexpr int kW = 32, kH = 24;
constexpr std::int64_t kPeriodNs = 20'000'000;  // 50 fps

std::uint8_t pixel_of(int camera, std::int64_t frame) {
  return static_cast<std::uint8_t>(10 + 40 * camera + frame);
}

// Frames 0..5 for cam0 and cam1; cam1/000003.pgm absent; cam0/000004.pgm malformed.
void write_recording(const std::string& dir) {
  Rig rig;
  for (int c = 0; c < 2; ++c) {
    CameraModel m;
    m.name = "cam" + std::to_string(c);
    m.width = kW;
    m.height = kH;
    m.fx = m.fy = 40.0;
    m.cx = 15.5;
    m.cy = 11.5;
    m.t_cam_world = Vec3(-100.0 * c, 0.0, 0.0);
    rig.cameras.push_back(m);
  }
  std::filesystem::create_directories(dir + "/cam0");
  std::filesystem::create_directories(dir + "/cam1");
  ASSERT_TRUE(save_rig(dir + "/rig.yaml", rig).ok());
  std::vector<FrameEntry> frames;
  for (std::int64_t f = 0; f < 6; ++f) {
    frames.push_back({f, 5'000'000'000 + f * kPeriodNs});
    for (int c = 0; c < 2; ++c) {
      if (c == 1 && f == 3) continue;
      Image im(kW, kH, PixelFormat::kMono8, 255);
      for (int y = 0; y < kH; ++y) {
        for (int x = 0; x < kW; ++x) im.row8(y)[x] = pixel_of(c, f);
      }
      ASSERT_TRUE(write_pgm(frame_file_path(dir, "cam" + std::to_string(c), f), im.view()).ok());
    }
  }
  mocap::test::write_file(frame_file_path(dir, "cam0", 4), "P5\n32 24\n255\nshort");
  ASSERT_TRUE(save_frames_csv(dir + "/frames.csv", frames).ok());
}

struct ReplayFixture : ::testing::Test {
  mocap::test::TempDir tmp{"replay"};
  std::shared_ptr<const Recording> rec;
  void SetUp() override {
    write_recording(tmp.path());
    auto r = Recording::open(tmp.path());
    ASSERT_TRUE(r.ok()) << r.error().message;
    rec = std::make_shared<const Recording>(std::move(*r));
  }
  std::unique_ptr<ReplayCamera> camera(int index, ReplayPacing pacing,
                                       TriggerMode trigger = TriggerMode::kFreeRun) {
    auto cam = ReplayCamera::open(rec, index, pacing);
    EXPECT_TRUE(cam.ok());
    CameraConfig cfg = (*cam)->native_config();
    cfg.trigger = trigger;
    cfg.buffer_count = 2;
    EXPECT_TRUE((*cam)->configure(cfg).ok());
    EXPECT_TRUE((*cam)->start().ok());
    return std::move(*cam);
  }
};

TEST_F(ReplayFixture, PlaysEveryFrameAndMarksMissingOnes) {
  auto cam1 = camera(1, ReplayPacing::kAsFastAsPossible);
  auto cam0 = camera(0, ReplayPacing::kAsFastAsPossible);
  for (std::int64_t f = 0; f < 6; ++f) {
    Frame a, b;
    ASSERT_EQ(cam0->dequeue(a, 100), CameraStatus::kOk);
    ASSERT_EQ(cam1->dequeue(b, 100), CameraStatus::kOk);
    EXPECT_EQ(a.sequence, static_cast<std::uint64_t>(f));
    EXPECT_EQ(b.sequence, static_cast<std::uint64_t>(f));
    EXPECT_EQ(a.timestamp_ns, 5'000'000'000 + f * kPeriodNs);
    EXPECT_EQ(a.missing, f == 4);  // malformed file
    EXPECT_EQ(b.missing, f == 3);  // absent file
    if (!a.missing) {
      ASSERT_EQ(a.image.width, kW);
      EXPECT_EQ(a.image.row8(kH - 1)[kW - 1], pixel_of(0, f));
    } else {
      EXPECT_TRUE(a.image.empty());
    }
    if (!b.missing) {
      EXPECT_EQ(b.image.row8(3)[7], pixel_of(1, f));
    }
    EXPECT_EQ(cam0->release(a), CameraStatus::kOk);
    EXPECT_EQ(cam1->release(b), CameraStatus::kOk);
  }
  Frame end;
  EXPECT_EQ(cam0->dequeue(end, 100), CameraStatus::kEndOfStream);
  EXPECT_EQ(cam1->counters().missing.get(), 1u);
  EXPECT_EQ(cam0->counters().errors.get(), 1u);
  EXPECT_EQ(cam0->counters().frames.get(), 6u);
  EXPECT_EQ(cam0->counters().dropped.get(), 0u);
}

TEST_F(ReplayFixture, RecordedTimingNeverDeliversEarly) {
  // The camera's start time is >= t_before, so frame i is due no earlier than
  // t_before + i * period: a lower bound that holds however loaded the machine is.
  const std::int64_t t_before = monotonic_ns();
  auto cam = camera(0, ReplayPacing::kRecordedTiming);
  Frame f;
  for (std::int64_t i = 0; i < 4; ++i) {
    ASSERT_EQ(cam->dequeue(f, 1000), CameraStatus::kOk);
    EXPECT_GE(f.received_ns - t_before, i * kPeriodNs);
    ASSERT_EQ(cam->release(f), CameraStatus::kOk);
  }
  // Before frame 4 is due, a zero timeout is a timeout, not a frame.
  const CameraStatus s = cam->dequeue(f, 0);
  if (monotonic_ns() < t_before + 4 * kPeriodNs) {
    EXPECT_EQ(s, CameraStatus::kTimeout);
    EXPECT_EQ(cam->counters().timeouts.get(), 1u);
  } else {
    EXPECT_TRUE(s == CameraStatus::kTimeout || s == CameraStatus::kOk);  // the machine stalled
  }
}

// The recording's timestamps stay the data's (5 s + i x 20 ms here, long before this
// process started); the latencies start at the delivery, on this host's clock.
TEST_F(ReplayFixture, KeepsTheRecordedTimestampAndStampsTheDelivery) {
  auto cam = camera(0, ReplayPacing::kAsFastAsPossible);
  for (std::int64_t i = 0; i < 3; ++i) {
    Frame f;
    const std::int64_t before = monotonic_ns();
    ASSERT_EQ(cam->dequeue(f, 100), CameraStatus::kOk);
    const std::int64_t after = monotonic_ns();
    EXPECT_EQ(f.timestamp_ns, 5'000'000'000 + i * kPeriodNs);
    EXPECT_GE(f.delivered_ns, before);
    EXPECT_LE(f.delivered_ns, after);
    EXPECT_EQ(latency_origin_ns(f), f.delivered_ns);
    ASSERT_EQ(cam->release(f), CameraStatus::kOk);
  }
  // A live camera's frame (delivered_ns 0): its timestamp is the local instant.
  Frame live;
  live.timestamp_ns = 123'456'789;
  EXPECT_EQ(latency_origin_ns(live), 123'456'789);
}

TEST_F(ReplayFixture, SoftwareTriggerReleasesOneFrameEach) {
  auto cam = camera(0, ReplayPacing::kAsFastAsPossible, TriggerMode::kSoftware);
  Frame f;
  EXPECT_EQ(cam->dequeue(f, 0), CameraStatus::kTimeout);
  ASSERT_EQ(cam->trigger(), CameraStatus::kOk);
  ASSERT_EQ(cam->trigger(), CameraStatus::kOk);
  ASSERT_EQ(cam->dequeue(f, 1000), CameraStatus::kOk);
  EXPECT_EQ(f.sequence, 0u);
  ASSERT_EQ(cam->release(f), CameraStatus::kOk);
  ASSERT_EQ(cam->dequeue(f, 1000), CameraStatus::kOk);
  EXPECT_EQ(f.sequence, 1u);
  EXPECT_EQ(cam->dequeue(f, 0), CameraStatus::kTimeout);
}

// Software-triggered, a frame's latencies start at the trigger that released it (as a
// live camera's exposure, and as a camera node's frame on the central), not at its
// delivery: each origin lies between the clock reads around its own trigger.
TEST_F(ReplayFixture, SoftwareTriggeredFramesStartTheirLatenciesAtTheirTrigger) {
  auto cam = camera(0, ReplayPacing::kAsFastAsPossible, TriggerMode::kSoftware);
  const std::int64_t t0 = monotonic_ns();
  ASSERT_EQ(cam->trigger(), CameraStatus::kOk);
  const std::int64_t t1 = monotonic_ns();
  ASSERT_EQ(cam->trigger(), CameraStatus::kOk);
  const std::int64_t t2 = monotonic_ns();
  Frame f;
  for (const auto& [from, to] : {std::pair{t0, t1}, std::pair{t1, t2}}) {
    ASSERT_EQ(cam->dequeue(f, 1000), CameraStatus::kOk);
    EXPECT_GE(latency_origin_ns(f), from);
    EXPECT_LE(latency_origin_ns(f), to);
    EXPECT_LE(f.delivered_ns, f.received_ns);
    ASSERT_EQ(cam->release(f), CameraStatus::kOk);
  }
}

// A camera node's `trigger: central` replay: seek() makes the named frame the next one
// (its image, number and timestamp), never an earlier one; past the end: end of stream.
TEST_F(ReplayFixture, SeekPlaysTheNamedFrameAndNeverGoesBack) {
  auto cam = camera(0, ReplayPacing::kAsFastAsPossible, TriggerMode::kSoftware);
  Frame f;
  ASSERT_EQ(cam->trigger(), CameraStatus::kOk);
  ASSERT_EQ(cam->dequeue(f, 1000), CameraStatus::kOk);
  EXPECT_EQ(f.sequence, 0u);
  ASSERT_EQ(cam->release(f), CameraStatus::kOk);
  ASSERT_EQ(cam->seek(1), CameraStatus::kOk);  // in step: nothing skipped
  EXPECT_EQ(cam->skipped(), 0u);
  ASSERT_EQ(cam->seek(3), CameraStatus::kOk);  // frames 1 and 2 (loaded ahead) passed over
  EXPECT_EQ(cam->skipped(), 2u);
  ASSERT_EQ(cam->trigger(), CameraStatus::kOk);
  ASSERT_EQ(cam->dequeue(f, 1000), CameraStatus::kOk);
  EXPECT_EQ(f.sequence, 3u);
  EXPECT_EQ(f.timestamp_ns, 5'000'000'000 + 3 * kPeriodNs);
  ASSERT_FALSE(f.image.empty());
  EXPECT_EQ(f.image.row8(0)[0], pixel_of(0, 3));
  ASSERT_EQ(cam->release(f), CameraStatus::kOk);
  EXPECT_EQ(cam->counters().dropped.get(), 0u);         // a seek is not a camera drop
  EXPECT_EQ(cam->seek(2), CameraStatus::kUnsupported);  // played already
  ASSERT_EQ(cam->trigger(), CameraStatus::kOk);
  ASSERT_EQ(cam->dequeue(f, 1000), CameraStatus::kOk);
  EXPECT_EQ(f.sequence, 4u);
  ASSERT_EQ(cam->release(f), CameraStatus::kOk);
  ASSERT_EQ(cam->seek(99), CameraStatus::kOk);  // past the end
  EXPECT_EQ(cam->skipped(), 3u);                // frame 5
  ASSERT_EQ(cam->trigger(), CameraStatus::kOk);
  EXPECT_EQ(cam->dequeue(f, 0), CameraStatus::kEndOfStream);
}

TEST_F(ReplayFixture, BufferExhaustionAndBadRelease) {
  auto cam = camera(0, ReplayPacing::kAsFastAsPossible);
  Frame a, b, c;
  ASSERT_EQ(cam->dequeue(a, 1000), CameraStatus::kOk);
  ASSERT_EQ(cam->dequeue(b, 1000), CameraStatus::kOk);
  EXPECT_NE(a.image.data, b.image.data);
  EXPECT_EQ(cam->dequeue(c, 1000), CameraStatus::kNoBuffer);
  EXPECT_EQ(cam->counters().no_buffer.get(), 1u);
  ASSERT_EQ(cam->release(a), CameraStatus::kOk);
  EXPECT_EQ(cam->release(a), CameraStatus::kInvalidBuffer);
  ASSERT_EQ(cam->dequeue(c, 1000), CameraStatus::kOk);
  EXPECT_EQ(c.sequence, 2u);  // the frame is not lost by kNoBuffer
}

TEST_F(ReplayFixture, ConfigurationErrors) {
  auto cam = ReplayCamera::open(rec, 0, ReplayPacing::kAsFastAsPossible);
  ASSERT_TRUE(cam.ok());
  CameraConfig cfg = (*cam)->native_config();
  cfg.width = 640;
  auto r = (*cam)->configure(cfg);
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.error().message.find("size: the recording's images are 32x24, configured 640x24"),
            std::string::npos)
      << r.error().message;
  EXPECT_FALSE(ReplayCamera::open(rec, 2, ReplayPacing::kAsFastAsPossible).ok());
  cfg = (*cam)->native_config();
  cfg.trigger = TriggerMode::kExternal;
  cfg.exposure_us = 500;
  ASSERT_TRUE((*cam)->configure(cfg).ok());
  EXPECT_EQ((*cam)->config().trigger, TriggerMode::kFreeRun);
  EXPECT_NE((*cam)->notice().find("no external trigger"), std::string::npos);
  Frame f;
  EXPECT_EQ((*cam)->dequeue(f, 0), CameraStatus::kNotStreaming);
}

TEST_F(ReplayFixture, SteadyStateAllocatesNothing) {
  auto cam = camera(1, ReplayPacing::kAsFastAsPossible);
  Frame f;
  ASSERT_EQ(cam->dequeue(f, 1000), CameraStatus::kOk);  // warm-up
  ASSERT_EQ(cam->release(f), CameraStatus::kOk);
  mocap::test::AllocationScope scope;
  for (int i = 0; i < 2; ++i) {  // frames 1 and 2 (3 is missing: its error path may allocate)
    ASSERT_EQ(cam->dequeue(f, 1000), CameraStatus::kOk);
    ASSERT_EQ(cam->release(f), CameraStatus::kOk);
  }
  EXPECT_EQ(scope.count(), 0u);
}

}  // namespace
}  // namespace mocap::hal
