// Design: the replay's loader thread (hal/replay_read_ahead.h) against a consumer on
// the test thread: every frame delivered once, in the recording's order, with its own
// pixels and status (absent, malformed, 16-bit where 8-bit is expected); a consumer that
// holds every buffer stops the loader without losing a frame; destruction while the
// loader waits or works; a long stress with one to three buffers and a consumer that
// keeps buffers for random times (run under TSan: label "concurrency"); a camera restart
// replays from the first frame; setup errors are one line.
#include <gtest/gtest.h>

#include <chrono>
#include <deque>
#include <memory>
#include <random>
#include <thread>

#include "core/clock.h"
#include "formats/pgm.h"
#include "formats/rig_yaml.h"
#include "hal/replay_camera.h"
#include "hal/replay_read_ahead.h"
#include "tests/support/test_support.h"

namespace mocap::hal {
namespace {

constexpr int kAheadW = 24, kAheadH = 10;

std::uint8_t ahead_pixel(std::int64_t frame) { return static_cast<std::uint8_t>(frame * 7 + 3); }

// n frames of one camera "cam0"; frame 5 absent, frame 9 malformed, frame 11 16-bit.
std::shared_ptr<const Recording> write_ahead_recording(const std::string& dir, int n) {
  Rig rig;
  CameraModel m;
  m.name = "cam0";
  m.width = kAheadW;
  m.height = kAheadH;
  m.fx = m.fy = 30.0;
  m.cx = 11.5;
  m.cy = 4.5;
  rig.cameras.push_back(m);
  std::filesystem::create_directories(dir + "/cam0");
  EXPECT_TRUE(save_rig(dir + "/rig.yaml", rig).ok());
  std::vector<FrameEntry> frames;
  for (std::int64_t f = 0; f < n; ++f) {
    frames.push_back({f, 1'000'000 + f * 10'000'000});
    if (f == 5) continue;
    const bool wide = f == 11;
    Image im(kAheadW, kAheadH, wide ? PixelFormat::kMono16 : PixelFormat::kMono8,
             wide ? 4095 : 255);
    for (int y = 0; y < kAheadH; ++y)
      for (int x = 0; x < kAheadW; ++x) {
        if (wide) {
          im.row16(y)[x] = ahead_pixel(f);
        } else {
          im.row8(y)[x] = ahead_pixel(f);
        }
      }
    EXPECT_TRUE(write_pgm(frame_file_path(dir, "cam0", f), im.view()).ok());
  }
  mocap::test::write_file(frame_file_path(dir, "cam0", 9), "P5\n24 10\n255\ntruncated");
  EXPECT_TRUE(save_frames_csv(dir + "/frames.csv", frames).ok());
  auto rec = Recording::open(dir);
  EXPECT_TRUE(rec.ok()) << (rec.ok() ? "" : rec.error().message);
  return std::make_shared<const Recording>(std::move(*rec));
}

ReplayLoadStatus expected_status(std::int64_t f) {
  if (f == 5) return ReplayLoadStatus::kMissing;
  if (f == 9 || f == 11) return ReplayLoadStatus::kError;
  return ReplayLoadStatus::kOk;
}

std::unique_ptr<ReplayReadAhead> start_ahead(std::shared_ptr<const Recording> rec, int buffers) {
  auto ra = ReplayReadAhead::start(std::move(rec), 0, buffers, PixelFormat::kMono8, "test-ahead");
  EXPECT_TRUE(ra.ok()) << (ra.ok() ? "" : ra.error().message);
  return std::move(*ra);
}

// Checks one delivered frame: its index, status and (when loaded) every pixel.
void expect_frame(const ReplayReadAhead& ra, const ReplayLoaded& got, std::int64_t f) {
  ASSERT_EQ(got.frame_index, static_cast<std::uint32_t>(f));
  EXPECT_EQ(got.status, expected_status(f)) << "frame " << f;
  const Image& im = ra.image(got.buffer);
  ASSERT_EQ(im.format(), PixelFormat::kMono8);  // the pool keeps its format
  ASSERT_EQ(im.width(), kAheadW);
  if (got.status != ReplayLoadStatus::kOk) return;
  for (int y = 0; y < kAheadH; ++y)
    for (int x = 0; x < kAheadW; ++x) ASSERT_EQ(im.view().row8(y)[x], ahead_pixel(f));
}

TEST(ReplayReadAhead, DeliversEveryFrameInOrderWithItsStatus) {
  mocap::test::TempDir tmp{"ahead"};
  const auto rec = write_ahead_recording(tmp.path(), 16);
  for (int buffers : {1, 2, 5}) {
    auto ra = start_ahead(rec, buffers);
    for (std::int64_t f = 0; f < 16; ++f) {
      ReplayLoaded got;
      ASSERT_TRUE(ra->wait_next(got, monotonic_ns() + 5'000'000'000)) << "frame " << f;
      expect_frame(*ra, got, f);
      ra->give_back(got.buffer);
    }
    ReplayLoaded none;
    EXPECT_FALSE(ra->wait_next(none, monotonic_ns() + 20'000'000));  // the end: nothing more
  }
}

TEST(ReplayReadAhead, AConsumerHoldingEveryBufferLosesNoFrame) {
  mocap::test::TempDir tmp{"ahead"};
  const auto rec = write_ahead_recording(tmp.path(), 16);
  auto ra = start_ahead(rec, 3);
  std::vector<ReplayLoaded> held(3);
  for (int i = 0; i < 3; ++i) {
    ASSERT_TRUE(ra->wait_next(held[static_cast<std::size_t>(i)], monotonic_ns() + 5'000'000'000));
    expect_frame(*ra, held[static_cast<std::size_t>(i)], i);
  }
  ReplayLoaded extra;
  EXPECT_FALSE(ra->wait_next(extra, monotonic_ns() + 30'000'000));  // no buffer to load into
  ra->give_back(held[1].buffer);
  ASSERT_TRUE(ra->wait_next(extra, monotonic_ns() + 5'000'000'000));
  EXPECT_EQ(extra.buffer, held[1].buffer);
  expect_frame(*ra, extra, 3);    // the next frame, not one skipped while the pool was full
  expect_frame(*ra, held[0], 0);  // a held buffer is never written over
  expect_frame(*ra, held[2], 2);
}

TEST(ReplayReadAhead, DestructionWhileWaitingOrWorkingJoins) {
  mocap::test::TempDir tmp{"ahead"};
  const auto rec = write_ahead_recording(tmp.path(), 40);
  {
    auto ra = start_ahead(rec, 2);  // fills both buffers, then waits for one back
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  {
    auto ra = start_ahead(rec, 32);  // destroyed while (probably) still loading
  }
  SUCCEED();
}

// Producer and consumer at their own random paces, over and over: the order, pixels and
// statuses hold, and every buffer handed out is a distinct one while held.
TEST(ReplayReadAhead, StressWithFewBuffersKeepsOrderAndContent) {
  mocap::test::TempDir tmp{"ahead"};
  constexpr int kAheadFrames = 120;
  const auto rec = write_ahead_recording(tmp.path(), kAheadFrames);
  std::mt19937 rng(4);
  for (int buffers : {1, 2, 3}) {
    auto ra = start_ahead(rec, buffers);
    std::deque<ReplayLoaded> holding;
    for (std::int64_t f = 0; f < kAheadFrames; ++f) {
      ReplayLoaded got;
      ASSERT_TRUE(ra->wait_next(got, monotonic_ns() + 5'000'000'000)) << "frame " << f;
      for (const ReplayLoaded& h : holding) ASSERT_NE(h.buffer, got.buffer);
      expect_frame(*ra, got, f);
      holding.push_back(got);
      // Keep up to all buffers for a while, then give back the oldest.
      while (!holding.empty() && (static_cast<int>(holding.size()) == buffers || rng() % 3 == 0)) {
        if (rng() % 4 == 0) std::this_thread::sleep_for(std::chrono::microseconds(rng() % 300));
        ra->give_back(holding.front().buffer);
        holding.pop_front();
      }
    }
  }
}

TEST(ReplayReadAhead, SetupErrorsAreOneLine) {
  mocap::test::TempDir tmp{"ahead"};
  const auto rec = write_ahead_recording(tmp.path(), 3);
  for (auto [camera, buffers, name] :
       {std::tuple{1, 2, "ok-name"}, std::tuple{-1, 2, "ok-name"}, std::tuple{0, 0, "ok-name"},
        std::tuple{0, 2, "a-name-longer-than-15"}}) {
    auto ra = ReplayReadAhead::start(rec, camera, buffers, PixelFormat::kMono8, name);
    ASSERT_FALSE(ra.ok());
    EXPECT_EQ(ra.error().message.find('\n'), std::string::npos) << ra.error().message;
  }
}

TEST(ReplayReadAhead, ACameraRestartReplaysFromTheFirstFrame) {
  mocap::test::TempDir tmp{"ahead"};
  const auto rec = write_ahead_recording(tmp.path(), 8);
  auto cam = ReplayCamera::open(rec, 0, ReplayPacing::kAsFastAsPossible);
  ASSERT_TRUE(cam.ok());
  CameraConfig cfg = (*cam)->native_config();
  cfg.buffer_count = 2;
  ASSERT_TRUE((*cam)->configure(cfg).ok());
  for (int run = 0; run < 3; ++run) {
    ASSERT_TRUE((*cam)->start().ok());
    for (std::int64_t f = 0; f < 3 + run; ++f) {
      Frame frame;
      ASSERT_EQ((*cam)->dequeue(frame, 1000), CameraStatus::kOk);
      EXPECT_EQ(frame.sequence, static_cast<std::uint64_t>(f));
      if (!frame.missing) {
        EXPECT_EQ(frame.image.row8(0)[0], ahead_pixel(f));
      }
      ASSERT_EQ((*cam)->release(frame), CameraStatus::kOk);
    }
    (*cam)->stop();
  }
}

}  // namespace
}  // namespace mocap::hal
