// The V4L2 backend against the fake device: open errors, format negotiation,
// controls, buffer cycling with sequence numbers and timestamps, drops, timeouts,
// EAGAIN/EIO/ENODEV, corrupt frames, trigger modes, the state machine, and no heap
// allocation in the dequeue/release cycle.
#include <gtest/gtest.h>

#include <cerrno>
#include <memory>

#include "hal/v4l2_camera.h"
#include "tests/hal/fake_v4l2.h"
#include "tests/support/alloc_counter.h"

namespace mocap::hal {
namespace {

using test::FakeControl;
using test::FakeV4l2;

std::shared_ptr<FakeV4l2> make_fake() {
  auto fake = std::make_shared<FakeV4l2>();
  fake->controls[V4L2_CID_EXPOSURE_AUTO] =
      FakeControl{"Auto Exposure", V4L2_CTRL_TYPE_MENU, 0, 3, 1, 0, {}};
  fake->controls[V4L2_CID_EXPOSURE_ABSOLUTE] =
      FakeControl{"Exposure Time, Absolute", V4L2_CTRL_TYPE_INTEGER, 1, 5000, 1, 100, {}};
  fake->controls[V4L2_CID_GAIN] = FakeControl{"Gain", V4L2_CTRL_TYPE_INTEGER, 0, 480, 1, 0, {}};
  return fake;
}

CameraConfig grey_config() {
  CameraConfig c;
  c.format = PixelFormat::kMono8;
  c.width = 64;
  c.height = 48;
  c.exposure_us = 2000;
  c.gain = 100;
  c.frame_rate_hz = 100.0;
  c.buffer_count = 4;
  return c;
}

std::unique_ptr<V4l2Camera> open_configured(const std::shared_ptr<FakeV4l2>& fake,
                                            const CameraConfig& cfg) {
  auto cam = V4l2Camera::open(fake->path, fake);
  EXPECT_TRUE(cam.ok()) << cam.error().message;
  if (!cam.ok()) return nullptr;
  auto r = (*cam)->configure(cfg);
  EXPECT_TRUE(r.ok()) << r.error().message;
  return std::move(*cam);
}

TEST(V4l2Camera, AbsentDeviceNamesThePath) {
  auto fake = make_fake();
  auto cam = V4l2Camera::open("/dev/video7", fake);
  ASSERT_FALSE(cam.ok());
  EXPECT_EQ(cam.error().message, "/dev/video7: cannot open: No such file or directory");
}

TEST(V4l2Camera, RealSystemAbsentDevice) {
  auto cam = V4l2Camera::open("/dev/mocap-no-such-video-device");
  ASSERT_FALSE(cam.ok());
  EXPECT_EQ(cam.error().message.rfind("/dev/mocap-no-such-video-device: cannot open: ", 0), 0u)
      << cam.error().message;
}

TEST(V4l2Camera, RejectsDevicesWithoutStreamingCapture) {
  auto fake = make_fake();
  fake->capabilities = V4L2_CAP_VIDEO_CAPTURE;  // read() I/O only
  auto cam = V4l2Camera::open(fake->path, fake);
  ASSERT_FALSE(cam.ok());
  EXPECT_NE(cam.error().message.find("streaming"), std::string::npos) << cam.error().message;
  EXPECT_EQ(fake->open_fds, 0);  // closed again
}

TEST(V4l2Camera, FormatNegotiationMismatchIsAClearError) {
  auto fake = make_fake();
  auto cam = V4l2Camera::open(fake->path, fake);
  ASSERT_TRUE(cam.ok());
  CameraConfig cfg = grey_config();
  cfg.width = 1280;
  cfg.height = 1024;
  auto r = (*cam)->configure(cfg);
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.error().message,
            "/dev/video-fake: format: driver offers 64x48 GREY for the requested 1280x1024 GREY");
  EXPECT_EQ((*cam)->state(), CameraState::kClosed);

  fake->modes = {{V4L2_PIX_FMT_GREY, 64, 48}};  // no Y16
  cfg = grey_config();
  cfg.format = PixelFormat::kMono16;
  r = (*cam)->configure(cfg);
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.error().message,
            "/dev/video-fake: format: driver offers 64x48 GREY for the requested 64x48 Y16");
}

TEST(V4l2Camera, ConfiguresControlsAndRate) {
  auto fake = make_fake();
  auto cam = open_configured(fake, grey_config());
  ASSERT_TRUE(cam);
  EXPECT_EQ(cam->state(), CameraState::kConfigured);
  EXPECT_EQ(fake->controls[V4L2_CID_EXPOSURE_AUTO].value, V4L2_EXPOSURE_MANUAL);
  EXPECT_EQ(fake->controls[V4L2_CID_EXPOSURE_ABSOLUTE].value, 20);  // 100 us units
  EXPECT_EQ(fake->controls[V4L2_CID_GAIN].value, 100);
  EXPECT_EQ(cam->config().exposure_us, 2000);
  EXPECT_DOUBLE_EQ(cam->config().frame_rate_hz, 100.0);
  EXPECT_TRUE(cam->notice().empty()) << cam->notice();
}

TEST(V4l2Camera, ControlErrorsNameTheSetting) {
  auto fake = make_fake();
  auto cam = V4l2Camera::open(fake->path, fake);
  ASSERT_TRUE(cam.ok());
  CameraConfig cfg = grey_config();
  cfg.exposure_us = 900'000;
  auto r = (*cam)->configure(cfg);
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.error().message,
            "/dev/video-fake: exposure_us: 900000 outside the device's range 100..500000 us");
  cfg = grey_config();
  cfg.gain = 1000;
  r = (*cam)->configure(cfg);
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.error().message, "/dev/video-fake: gain: 1000 outside the device's range 0..480");
  fake->controls.erase(V4L2_CID_EXPOSURE_ABSOLUTE);
  r = (*cam)->configure(grey_config());
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.error().message.find("exposure_us: the device has no V4L2_CID_EXPOSURE_ABSOLUTE"),
            std::string::npos);
  cfg = grey_config();
  cfg.buffer_count = 1;
  EXPECT_FALSE((*cam)->configure(cfg).ok());
}

TEST(V4l2Camera, BuffersCycleWithSequenceAndTimestamps) {
  auto fake = make_fake();
  fake->row_padding_bytes = 16;
  auto cam = open_configured(fake, grey_config());
  ASSERT_TRUE(cam);
  ASSERT_TRUE(cam->start().ok());
  EXPECT_EQ(cam->state(), CameraState::kStreaming);
  EXPECT_EQ(fake->mapped, 4);
  EXPECT_EQ(fake->queued_count(), 4u);
  Frame held;  // keep one frame out, as a pipeline does
  bool holding = false;
  for (int i = 0; i < 1000; ++i) {
    ASSERT_TRUE(fake->emit_frame(static_cast<std::uint8_t>(i)));
    Frame f;
    ASSERT_EQ(cam->dequeue(f, 10), CameraStatus::kOk) << i;
    EXPECT_EQ(f.sequence, static_cast<std::uint64_t>(i));
    EXPECT_EQ(f.timestamp_ns, fake->last_timestamp_ns);
    EXPECT_GT(f.received_ns, 0);
    ASSERT_EQ(f.image.width, 64);
    ASSERT_EQ(f.image.height, 48);
    EXPECT_EQ(f.image.stride_bytes, 80);
    EXPECT_EQ(f.image.format, PixelFormat::kMono8);
    EXPECT_EQ(f.image.row8(47)[63], static_cast<std::uint8_t>(i));
    if (holding) {
      EXPECT_EQ(cam->release(held), CameraStatus::kOk);
    }
    held = f;
    holding = true;
  }
  EXPECT_EQ(cam->release(held), CameraStatus::kOk);
  EXPECT_EQ(cam->counters().frames.get(), 1000u);
  EXPECT_EQ(cam->counters().dropped.get(), 0u);
  EXPECT_EQ(cam->counters().errors.get(), 0u);
  EXPECT_EQ(fake->queued_count(), 4u);
  cam->stop();
  EXPECT_EQ(cam->state(), CameraState::kConfigured);
  EXPECT_EQ(fake->mapped, 0);
  EXPECT_EQ(fake->buffer_count(), 0u);
  // Restart works.
  ASSERT_TRUE(cam->start().ok());
  ASSERT_TRUE(fake->emit_frame(9));
  Frame f;
  EXPECT_EQ(cam->dequeue(f, 10), CameraStatus::kOk);
}

TEST(V4l2Camera, Y16FramesAndSequenceWrap) {
  auto fake = make_fake();
  CameraConfig cfg = grey_config();
  cfg.format = PixelFormat::kMono16;
  auto cam = open_configured(fake, cfg);
  ASSERT_TRUE(cam);
  ASSERT_TRUE(cam->start().ok());
  fake->set_sequence(0xFFFFFFFEu);
  std::uint64_t expect = 0xFFFFFFFEull;
  for (int i = 0; i < 5; ++i) {
    ASSERT_TRUE(fake->emit_frame(0x12));
    Frame f;
    ASSERT_EQ(cam->dequeue(f, 10), CameraStatus::kOk);
    EXPECT_EQ(f.sequence, expect++);
    EXPECT_EQ(f.image.format, PixelFormat::kMono16);
    EXPECT_EQ(f.image.stride_bytes, 128);
    EXPECT_EQ(f.image.maxval, 65535);
    EXPECT_EQ(f.image.row16(3)[5], 0x1212);
    ASSERT_EQ(cam->release(f), CameraStatus::kOk);
  }
  EXPECT_EQ(cam->counters().dropped.get(), 0u);
}

TEST(V4l2Camera, GapsAndDriverDropsAreCounted) {
  auto fake = make_fake();
  auto cam = open_configured(fake, grey_config());
  ASSERT_TRUE(cam);
  ASSERT_TRUE(cam->start().ok());
  Frame f[4];
  for (int i = 0; i < 4; ++i) {  // the caller holds every buffer
    ASSERT_TRUE(fake->emit_frame(1));
    ASSERT_EQ(cam->dequeue(f[i], 10), CameraStatus::kOk);
  }
  EXPECT_FALSE(fake->emit_frame(2));  // no queued buffer: the driver drops frame 4
  EXPECT_EQ(cam->dequeue(f[0], 0), CameraStatus::kTimeout);
  for (int i = 0; i < 4; ++i) ASSERT_EQ(cam->release(f[i]), CameraStatus::kOk);
  fake->skip_sequence(3);  // frames 5..7 lost in the driver
  ASSERT_TRUE(fake->emit_frame(3));
  Frame g;
  ASSERT_EQ(cam->dequeue(g, 10), CameraStatus::kOk);
  EXPECT_EQ(g.sequence, 8u);
  EXPECT_EQ(cam->counters().dropped.get(), 4u);
  EXPECT_EQ(cam->counters().timeouts.get(), 1u);
}

TEST(V4l2Camera, ErrorsMidStream) {
  auto fake = make_fake();
  auto cam = open_configured(fake, grey_config());
  ASSERT_TRUE(cam);
  ASSERT_TRUE(cam->start().ok());
  Frame f;
  // EAGAIN: woken without a frame; not an error.
  fake->emit_frame(1);
  fake->fail_next_dqbuf_errno = EAGAIN;
  EXPECT_EQ(cam->dequeue(f, 10), CameraStatus::kAgain);
  EXPECT_EQ(cam->counters().errors.get(), 0u);
  ASSERT_EQ(cam->dequeue(f, 10), CameraStatus::kOk);
  ASSERT_EQ(cam->release(f), CameraStatus::kOk);
  // EIO: counted, the stream goes on.
  fake->emit_frame(2);
  fake->fail_next_dqbuf_errno = EIO;
  EXPECT_EQ(cam->dequeue(f, 10), CameraStatus::kIoError);
  EXPECT_EQ(cam->counters().errors.get(), 1u);
  EXPECT_EQ(cam->state(), CameraState::kStreaming);
  ASSERT_EQ(cam->dequeue(f, 10), CameraStatus::kOk);
  // Corrupt (flagged) and short frames: requeued, counted.
  ASSERT_EQ(cam->release(f), CameraStatus::kOk);
  fake->emit_frame(3, /*error_flag=*/true);
  EXPECT_EQ(cam->dequeue(f, 10), CameraStatus::kCorruptFrame);
  fake->emit_frame(4, false, /*bytesused=*/100);
  EXPECT_EQ(cam->dequeue(f, 10), CameraStatus::kCorruptFrame);
  EXPECT_EQ(cam->counters().errors.get(), 3u);
  EXPECT_EQ(fake->queued_count(), 4u);
  // Releasing a frame that is not out is refused.
  Frame bogus;
  bogus.buffer_index = 2;
  EXPECT_EQ(cam->release(bogus), CameraStatus::kInvalidBuffer);
  bogus.buffer_index = 99;
  EXPECT_EQ(cam->release(bogus), CameraStatus::kInvalidBuffer);
  // ENODEV: the device is gone -> kError, and it stays there.
  fake->unplugged = true;
  EXPECT_EQ(cam->dequeue(f, 10), CameraStatus::kDeviceLost);
  EXPECT_EQ(cam->state(), CameraState::kError);
  EXPECT_EQ(cam->dequeue(f, 10), CameraStatus::kDeviceLost);
  EXPECT_EQ(cam->trigger(), CameraStatus::kDeviceLost);
  EXPECT_FALSE(cam->configure(grey_config()).ok());
  cam->stop();
  EXPECT_EQ(fake->mapped, 0);
  cam.reset();
  EXPECT_EQ(fake->open_fds, 0);
}

TEST(V4l2Camera, WrongStateCalls) {
  auto fake = make_fake();
  auto cam = V4l2Camera::open(fake->path, fake);
  ASSERT_TRUE(cam.ok());
  Frame f;
  EXPECT_EQ((*cam)->dequeue(f, 0), CameraStatus::kNotStreaming);
  EXPECT_FALSE((*cam)->start().ok());
  ASSERT_TRUE((*cam)->configure(grey_config()).ok());
  EXPECT_EQ((*cam)->trigger(), CameraStatus::kNotStreaming);
  ASSERT_TRUE((*cam)->start().ok());
  EXPECT_EQ((*cam)->trigger(), CameraStatus::kUnsupported);  // free-run
  auto again = (*cam)->configure(grey_config());
  ASSERT_FALSE(again.ok());
  EXPECT_EQ(again.error().message, "/dev/video-fake: configure: stop streaming first");
}

TEST(V4l2Camera, NoTriggerControlFallsBackToFreeRun) {
  auto fake = make_fake();
  CameraConfig cfg = grey_config();
  cfg.trigger = TriggerMode::kExternal;
  auto cam = open_configured(fake, cfg);
  ASSERT_TRUE(cam);
  EXPECT_EQ(cam->config().trigger, TriggerMode::kFreeRun);
  EXPECT_EQ(cam->notice(),
            "/dev/video-fake: trigger: no trigger-mode control: camera free-runs (pair frames by "
            "timestamp)");
}

TEST(V4l2Camera, ExternalTriggerThroughPrivateControl) {
  auto fake = make_fake();
  fake->controls[V4L2_CID_PRIVATE_BASE + 3] =
      FakeControl{"trigger_mode", V4L2_CTRL_TYPE_BOOLEAN, 0, 1, 1, 0, {}};
  CameraConfig cfg = grey_config();
  cfg.trigger = TriggerMode::kExternal;
  auto cam = open_configured(fake, cfg);
  ASSERT_TRUE(cam);
  EXPECT_EQ(cam->config().trigger, TriggerMode::kExternal);
  EXPECT_EQ(fake->controls[V4L2_CID_PRIVATE_BASE + 3].value, 1);
  EXPECT_TRUE(cam->notice().empty());
}

TEST(V4l2Camera, MenuTriggerModeAndSoftwareTrigger) {
  auto fake = make_fake();
  const std::uint32_t mode_id = V4L2_CID_PRIVATE_BASE + 1, button_id = V4L2_CID_PRIVATE_BASE + 2;
  fake->controls[mode_id] =
      FakeControl{"Trigger Mode", V4L2_CTRL_TYPE_MENU, 0, 2, 1, 0, {"Off", "External", "Software"}};
  fake->controls[button_id] =
      FakeControl{"Software Trigger", V4L2_CTRL_TYPE_BUTTON, 0, 1, 1, 0, {}};
  fake->software_trigger_id = button_id;
  CameraConfig cfg = grey_config();
  cfg.trigger = TriggerMode::kSoftware;
  auto cam = open_configured(fake, cfg);
  ASSERT_TRUE(cam);
  EXPECT_EQ(cam->config().trigger, TriggerMode::kSoftware);
  EXPECT_EQ(fake->controls[mode_id].value, 2);
  ASSERT_TRUE(cam->start().ok());
  Frame f;
  EXPECT_EQ(cam->dequeue(f, 0), CameraStatus::kTimeout);  // nothing without a trigger
  for (std::uint64_t i = 0; i < 3; ++i) {
    ASSERT_EQ(cam->trigger(), CameraStatus::kOk);
    ASSERT_EQ(cam->dequeue(f, 10), CameraStatus::kOk);
    EXPECT_EQ(f.sequence, i);
    ASSERT_EQ(cam->release(f), CameraStatus::kOk);
  }
  // The same device asked for an external trigger picks the "External" item.
  cam->stop();
  cfg.trigger = TriggerMode::kExternal;
  ASSERT_TRUE(cam->configure(cfg).ok());
  EXPECT_EQ(fake->controls[mode_id].value, 1);
}

TEST(V4l2Camera, DequeueReleaseAllocateNothing) {
  auto fake = make_fake();
  auto cam = open_configured(fake, grey_config());
  ASSERT_TRUE(cam);
  ASSERT_TRUE(cam->start().ok());
  fake->auto_emit = true;
  Frame f;
  ASSERT_EQ(cam->dequeue(f, 10), CameraStatus::kOk);  // warm-up
  ASSERT_EQ(cam->release(f), CameraStatus::kOk);
  mocap::test::AllocationScope scope;
  for (int i = 0; i < 2000; ++i) {
    ASSERT_EQ(cam->dequeue(f, 10), CameraStatus::kOk);
    ASSERT_EQ(cam->release(f), CameraStatus::kOk);
  }
  EXPECT_EQ(scope.count(), 0u);
}

}  // namespace
}  // namespace mocap::hal
