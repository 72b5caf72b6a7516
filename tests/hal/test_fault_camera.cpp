// hal::FaultCamera on a scripted inner camera (no rendering, no files): the stall
// (kStall) holds the camera after N good frames without asking the inner camera, for a
// number of calls or for ever, then resumes with the frames that piled up; a sequence
// offset renumbers the frames of its rule only; the owning
// wrap() keeps the inner camera alive; a stall costs no allocation. The other fault
// kinds run through the live pipeline in tests/faults.
#include <gtest/gtest.h>

#include <memory>
#include <vector>

#include "hal/camera_base.h"
#include "hal/fault_camera.h"
#include "tests/support/alloc_counter.h"

namespace mocap::hal {
namespace {

// Each software trigger queues one frame (sequence = trigger number) of a fixed image.
class ScriptedCamera final : public CameraBase {
 public:
  ScriptedCamera() : CameraBase("scripted"), image_(8, 4, PixelFormat::kMono8, 7) {}
  Expected<void> configure(const CameraConfig& c) override {
    config_ = c;
    state_ = CameraState::kConfigured;
    return {};
  }
  Expected<void> start() override {
    state_ = CameraState::kStreaming;
    return {};
  }
  void stop() noexcept override { state_ = CameraState::kConfigured; }
  CameraStatus trigger() noexcept override {
    ++triggered_;
    return CameraStatus::kOk;
  }
  CameraStatus dequeue(Frame& out, int /*timeout_ms*/) noexcept override {
    if (dequeued_ == triggered_) return CameraStatus::kTimeout;
    out = Frame{};
    out.image = image_.view();
    out.sequence = dequeued_++;
    counters_.frames.add();
    return CameraStatus::kOk;
  }
  CameraStatus release(const Frame& /*frame*/) noexcept override { return CameraStatus::kOk; }

 private:
  Image image_;
  std::uint64_t triggered_ = 0;
  std::uint64_t dequeued_ = 0;
};

// Triggers and dequeues once; the sequence delivered, or -1 for a timeout.
std::int64_t trigger_and_take(Camera& cam) {
  EXPECT_EQ(cam.trigger(), CameraStatus::kOk);
  Frame f;
  const CameraStatus st = cam.dequeue(f, 1);
  if (st != CameraStatus::kOk) {
    EXPECT_EQ(st, CameraStatus::kTimeout);
    return -1;
  }
  EXPECT_EQ(cam.release(f), CameraStatus::kOk);
  return static_cast<std::int64_t>(f.sequence);
}

TEST(FaultCamera, StallForSomeCallsThenResumesWithThePiledUpFrames) {
  ScriptedCamera inner;
  auto cam = FaultCamera::wrap(inner, {{Fault::kStall, 2, 3, 0}});
  ASSERT_TRUE(cam) << cam.error().message;
  ASSERT_TRUE((*cam)->configure(CameraConfig{}));
  ASSERT_TRUE((*cam)->start());
  std::vector<std::int64_t> got;
  for (int i = 0; i < 7; ++i) got.push_back(trigger_and_take(**cam));
  // Frames 2..4 wait in the inner camera during the stall and come afterwards.
  EXPECT_EQ(got, (std::vector<std::int64_t>{0, 1, -1, -1, -1, 2, 3}));
  EXPECT_EQ((*cam)->injected(Fault::kStall), 3u);
  EXPECT_EQ((*cam)->injected_total(), 3u);
  EXPECT_EQ((*cam)->frames_seen(), 4u);
  EXPECT_STREQ(to_string(Fault::kStall), "stall");
}

TEST(FaultCamera, SequenceOffsetRenumbersOnlyTheFramesOfItsRule) {
  ScriptedCamera inner;
  auto cam = FaultCamera::wrap(inner, {{Fault::kSequenceOffset, 2, 3, 1000}});
  ASSERT_TRUE(cam) << cam.error().message;
  ASSERT_TRUE((*cam)->configure(CameraConfig{}));
  ASSERT_TRUE((*cam)->start());
  std::vector<std::int64_t> got;
  for (int i = 0; i < 6; ++i) got.push_back(trigger_and_take(**cam));
  EXPECT_EQ(got, (std::vector<std::int64_t>{0, 1, 1002, 1003, 1004, 5}));
  EXPECT_EQ((*cam)->injected(Fault::kSequenceOffset), 3u);
  EXPECT_STREQ(to_string(Fault::kSequenceOffset), "sequence_offset");
}

TEST(FaultCamera, OwningWrapStallsForeverWithoutAllocating) {
  auto owned = std::make_unique<ScriptedCamera>();
  const ScriptedCamera* inner = owned.get();
  auto cam = FaultCamera::wrap(std::move(owned), {{Fault::kStall, 1, FaultRule::kForever, 0}});
  ASSERT_TRUE(cam) << cam.error().message;
  ASSERT_TRUE((*cam)->configure(CameraConfig{}));
  ASSERT_TRUE((*cam)->start());
  EXPECT_EQ(trigger_and_take(**cam), 0);
  mocap::test::AllocationScope allocs;
  for (int i = 0; i < 20; ++i) EXPECT_EQ(trigger_and_take(**cam), -1);
  EXPECT_EQ(allocs.count(), 0u);
  EXPECT_EQ((*cam)->injected(Fault::kStall), 20u);
  EXPECT_EQ(inner->counters().frames.get(), 1u);  // the inner camera was not asked again
  (*cam)->stop();
  EXPECT_EQ((*cam)->state(), CameraState::kConfigured);
  EXPECT_FALSE(FaultCamera::wrap(std::unique_ptr<Camera>(), {}));
}

}  // namespace
}  // namespace mocap::hal
