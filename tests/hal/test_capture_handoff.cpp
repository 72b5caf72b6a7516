// The intended live pattern, under ThreadSanitizer: a capture thread owns the camera
// (V4L2 backend on the fake device) and passes each Frame (trivially copyable, a view
// into the mapped buffer) to a processing thread through an SpscRing; the processing
// thread reads the pixels and hands the Frame back through a return ring; only the
// capture thread calls release(). When the processing ring is full the capture thread
// drops the newest frame at once (release + count) instead of blocking. At the end,
// every frame is accounted for and every buffer is back with the driver.
#include <gtest/gtest.h>

#include <atomic>
#include <memory>
#include <thread>

#include "hal/v4l2_camera.h"
#include "rt/spsc_ring.h"
#include "tests/hal/fake_v4l2.h"

namespace mocap::hal {
namespace {

#if defined(__SANITIZE_THREAD__) || defined(__SANITIZE_ADDRESS__)
constexpr int kFrames = 3000;
#else
constexpr int kFrames = 30000;
#endif

TEST(CaptureHandoff, FramesCrossThreadsAndComeBack) {
  auto fake = std::make_shared<test::FakeV4l2>();
  fake->auto_emit = true;
  fake->max_buffers = 6;
  auto cam_or = V4l2Camera::open(fake->path, fake);
  ASSERT_TRUE(cam_or.ok());
  V4l2Camera& cam = **cam_or;
  CameraConfig cfg;
  cfg.width = 64;
  cfg.height = 48;
  cfg.exposure_us = 0;
  cfg.buffer_count = 6;
  ASSERT_TRUE(cam.configure(cfg).ok());
  ASSERT_TRUE(cam.start().ok());

  rt::SpscRing<Frame> to_stage(4);  // capture -> processing
  rt::SpscRing<Frame> returned(8);  // processing -> capture (holds every buffer)
  std::atomic<bool> capture_done{false};
  std::uint64_t processed = 0, bad_pixels = 0, out_of_order = 0;

  std::thread stage([&] {
    std::uint64_t last = 0;
    bool first = true;
    for (;;) {
      Frame f;
      if (!to_stage.try_pop(f)) {
        if (capture_done.load(std::memory_order_acquire) && !to_stage.can_pop()) break;
        continue;
      }
      // The fake fills frame s with (s & 0xff).
      if (f.image.row8(f.image.height - 1)[f.image.width - 1] !=
          static_cast<std::uint8_t>(f.sequence & 0xffu)) {
        ++bad_pixels;
      }
      if (!first && f.sequence <= last) ++out_of_order;
      first = false;
      last = f.sequence;
      ++processed;
      while (!returned.try_push(f)) {
      }
    }
  });

  std::uint64_t captured = 0, dropped_full = 0, release_errors = 0;
  for (int i = 0; i < kFrames; ++i) {
    Frame back;
    while (returned.try_pop(back)) release_errors += cam.release(back) != CameraStatus::kOk;
    Frame f;
    const CameraStatus s = cam.dequeue(f, 10);
    if (s != CameraStatus::kOk) continue;  // kTimeout: every buffer is out
    ++captured;
    if (!to_stage.try_push(f)) {  // the stage fell behind: drop this frame, never block
      ++dropped_full;
      release_errors += cam.release(f) != CameraStatus::kOk;
    }
  }
  capture_done.store(true, std::memory_order_release);
  stage.join();
  Frame back;
  while (returned.try_pop(back)) release_errors += cam.release(back) != CameraStatus::kOk;

  EXPECT_EQ(bad_pixels, 0u);
  EXPECT_EQ(out_of_order, 0u);
  EXPECT_EQ(release_errors, 0u);
  EXPECT_EQ(processed + dropped_full, captured);
  EXPECT_GT(processed, 0u);
  EXPECT_EQ(fake->queued_count() + fake->done_count(), 6u);  // every buffer back
  EXPECT_EQ(cam.counters().frames.get(), captured);
}

}  // namespace
}  // namespace mocap::hal
