// The simulated camera: a pre-rendered loop served as a triggered stereo pair. Checks
// that one software trigger on the master fires both cameras with the same sequence
// and timestamp, that images are views of the pre-rendered loop (ping-pong order),
// buffer accounting (kNoBuffer, kInvalidBuffer), free-run pacing, configuration
// errors, and 0 allocations in trigger/dequeue/release.
#include <gtest/gtest.h>

#include <cstring>

#include "hal/sim_camera.h"
#include "tests/support/alloc_counter.h"

namespace mocap::hal {
namespace {

std::shared_ptr<const SimFrameLoop> small_loop() {
  static std::shared_ptr<const SimFrameLoop> loop = [] {
    sim::SimOptions o;
    o.frames = 6;
    auto l = SimFrameLoop::render(o);
    EXPECT_TRUE(l.ok()) << (l.ok() ? "" : l.error().message);
    return l.ok() ? *l : nullptr;
  }();
  return loop;
}

struct Pair {
  std::unique_ptr<SimCamera> cam[2];
};

Pair open_pair(const std::shared_ptr<SimTrigger>& trig, int buffers = 4) {
  Pair p;
  for (int c = 0; c < 2; ++c) {
    auto cam = SimCamera::open(trig, c);
    EXPECT_TRUE(cam.ok());
    p.cam[c] = std::move(cam).value();
    CameraConfig cfg = p.cam[c]->native_config();
    cfg.buffer_count = buffers;
    EXPECT_TRUE(p.cam[c]->configure(cfg).ok());
    EXPECT_TRUE(p.cam[c]->start().ok());
  }
  return p;
}

TEST(SimFrameLoop, RendersBothCamerasWithMarkers) {
  auto loop = small_loop();
  ASSERT_TRUE(loop);
  EXPECT_EQ(loop->frames(), 6);
  for (int c = 0; c < 2; ++c) {
    const Image& im = loop->image(0, c);
    EXPECT_EQ(im.width(), loop->scene().rig.cameras[static_cast<std::size_t>(c)].width);
    int bright = 0;
    for (int y = 0; y < im.height(); ++y)
      for (int x = 0; x < im.width(); ++x) bright += im.view().row8(y)[x] > 100;
    EXPECT_GT(bright, 50) << "markers rendered in camera " << c;
  }
  EXPECT_EQ(loop->memory_bytes(),
            6u * 2u * static_cast<std::size_t>(loop->image(0, 0).size_bytes()));
  // Ping-pong: 0..5, 4..1, 0..
  const int want[] = {0, 1, 2, 3, 4, 5, 4, 3, 2, 1, 0, 1};
  for (std::uint64_t s = 0; s < 12; ++s) EXPECT_EQ(loop->frame_of_sequence(s), want[s]);
}

TEST(SimFrameLoop, RejectsShortLoop) {
  sim::SimOptions o;
  o.frames = 1;
  auto l = SimFrameLoop::render(o);
  ASSERT_FALSE(l.ok());
  EXPECT_NE(l.error().message.find("frames"), std::string::npos);
}

TEST(SimCamera, OneTriggerFiresBothCameras) {
  auto trig = std::make_shared<SimTrigger>(small_loop());
  Pair p = open_pair(trig);
  EXPECT_EQ(p.cam[1]->trigger(), CameraStatus::kUnsupported);  // slaved
  Frame f0, f1;
  EXPECT_EQ(p.cam[0]->dequeue(f0, 0), CameraStatus::kTimeout);  // nothing fired yet
  for (std::uint64_t s = 0; s < 14; ++s) {
    ASSERT_EQ(p.cam[0]->trigger(), CameraStatus::kOk);
    ASSERT_EQ(p.cam[0]->dequeue(f0, 100), CameraStatus::kOk);
    ASSERT_EQ(p.cam[1]->dequeue(f1, 100), CameraStatus::kOk);
    EXPECT_EQ(f0.sequence, s);
    EXPECT_EQ(f1.sequence, s);
    EXPECT_EQ(f0.timestamp_ns, f1.timestamp_ns);
    EXPECT_LE(f0.timestamp_ns, f0.received_ns);
    const int frame = small_loop()->frame_of_sequence(s);
    EXPECT_EQ(f0.image.data, small_loop()->image(frame, 0).data());  // zero-copy
    EXPECT_EQ(f1.image.data, small_loop()->image(frame, 1).data());
    EXPECT_EQ(p.cam[0]->release(f0), CameraStatus::kOk);
    EXPECT_EQ(p.cam[1]->release(f1), CameraStatus::kOk);
  }
  EXPECT_EQ(p.cam[0]->counters().frames.get(), 14u);
  EXPECT_EQ(p.cam[0]->counters().timeouts.get(), 1u);
}

TEST(SimCamera, BufferAccounting) {
  auto trig = std::make_shared<SimTrigger>(small_loop());
  Pair p = open_pair(trig, 2);
  Frame a, b, c;
  for (int i = 0; i < 3; ++i) p.cam[0]->trigger();
  ASSERT_EQ(p.cam[0]->dequeue(a, 0), CameraStatus::kOk);
  ASSERT_EQ(p.cam[0]->dequeue(b, 0), CameraStatus::kOk);
  EXPECT_EQ(p.cam[0]->dequeue(c, 0), CameraStatus::kNoBuffer);
  EXPECT_EQ(p.cam[0]->counters().no_buffer.get(), 1u);
  EXPECT_EQ(p.cam[0]->release(a), CameraStatus::kOk);
  EXPECT_EQ(p.cam[0]->release(a), CameraStatus::kInvalidBuffer);
  ASSERT_EQ(p.cam[0]->dequeue(c, 0), CameraStatus::kOk);
  EXPECT_EQ(c.sequence, 2u);  // the refused frame is still delivered afterwards
  p.cam[0]->stop();
  EXPECT_EQ(p.cam[0]->dequeue(c, 0), CameraStatus::kNotStreaming);
}

TEST(SimCamera, SkipsAheadWhenFarBehind) {
  auto trig = std::make_shared<SimTrigger>(small_loop());
  Pair p = open_pair(trig);
  for (std::uint64_t i = 0; i < SimTrigger::kTriggerRing + 10; ++i) p.cam[0]->trigger();
  Frame f;
  ASSERT_EQ(p.cam[1]->dequeue(f, 0), CameraStatus::kOk);
  EXPECT_EQ(f.sequence, SimTrigger::kTriggerRing + 9);
  EXPECT_EQ(p.cam[1]->counters().dropped.get(), SimTrigger::kTriggerRing + 9);
}

TEST(SimCamera, FreeRunPacesFrames) {
  auto trig = std::make_shared<SimTrigger>(small_loop());
  auto cam = SimCamera::open(trig, 0);
  ASSERT_TRUE(cam.ok());
  CameraConfig cfg = (*cam)->native_config();
  cfg.trigger = TriggerMode::kFreeRun;
  cfg.frame_rate_hz = 500.0;
  ASSERT_TRUE((*cam)->configure(cfg).ok());
  ASSERT_TRUE((*cam)->start().ok());
  Frame f;
  std::int64_t last = 0;
  for (std::uint64_t s = 0; s < 5; ++s) {
    ASSERT_EQ((*cam)->dequeue(f, 1000), CameraStatus::kOk);
    EXPECT_EQ(f.sequence, s);
    if (s > 0) {
      EXPECT_EQ(f.timestamp_ns - last, 2'000'000);
    }
    EXPECT_GE(f.received_ns, f.timestamp_ns);  // delivered no earlier than due
    last = f.timestamp_ns;
    (*cam)->release(f);
  }
}

TEST(SimCamera, ConfigurationErrorsNameTheSetting) {
  auto trig = std::make_shared<SimTrigger>(small_loop());
  auto cam = SimCamera::open(trig, 1);
  ASSERT_TRUE(cam.ok());
  CameraConfig cfg = (*cam)->native_config();
  cfg.width = 640;
  auto r = (*cam)->configure(cfg);
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.error().message.find("size"), std::string::npos);
  cfg = (*cam)->native_config();
  cfg.format = PixelFormat::kMono16;
  EXPECT_FALSE((*cam)->configure(cfg).ok());
  cfg = (*cam)->native_config();
  cfg.buffer_count = 1;
  EXPECT_FALSE((*cam)->configure(cfg).ok());
  EXPECT_FALSE((*cam)->start().ok());  // not configured
  EXPECT_FALSE(SimCamera::open(trig, 2).ok());
}

TEST(SimCamera, HotPathDoesNotAllocate) {
  auto trig = std::make_shared<SimTrigger>(small_loop());
  Pair p = open_pair(trig);
  Frame f0, f1;
  mocap::test::AllocationScope scope;
  for (int i = 0; i < 100; ++i) {
    p.cam[0]->trigger();
    p.cam[0]->dequeue(f0, 10);
    p.cam[1]->dequeue(f1, 10);
    p.cam[0]->release(f0);
    p.cam[1]->release(f1);
  }
  EXPECT_EQ(scope.count(), 0u);
  EXPECT_EQ(p.cam[1]->counters().frames.get(), 100u);
}

}  // namespace
}  // namespace mocap::hal
