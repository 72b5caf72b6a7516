// The pipeline's blob tap (`mocap record --blobs`, pipeline_options.h: BlobTap and
// every_frame) on the simulated stereo pair: each detect stage hands every frame
// it detected to the tap, in sequence order, with the blob list identification gets; with
// every_frame no frame is skipped for a newer one (detect#_skipped stays 0), so
// every frame a camera delivered reaches the tap unless counted as dropped at the capture
// (ring full) or for want of a blob slot. Counts, never timing: the same under load and TSan.
#include <gtest/gtest.h>

#include <array>

#include "tests/pipeline/pipeline_fixture.h"

namespace mocap::pipeline {
namespace {

// Detect thread c writes camera c's entries; the test reads them after stop() joined it.
class SequenceTap final : public BlobTap {
 public:
  void on_blobs(int camera, const hal::Frame& frame, bool present,
                const detect::BlobList& blobs) noexcept override {
    const auto c = static_cast<std::size_t>(camera);
    if (c >= 2) return;
    const std::size_t k = count[c]++;
    if (k >= sequence[c].size()) return;
    sequence[c][k] = frame.sequence;
    blob_count[c][k] = present ? static_cast<int>(blobs.size()) : -1;
  }
  std::array<std::size_t, 2> count{};
  std::array<std::array<std::uint64_t, 256>, 2> sequence{};
  std::array<std::array<int, 256>, 2> blob_count{};
};

void run_with_tap(TriggerPacing pacing, double rate_hz) {
  test::SimRigFixture rig;
  SequenceTap tap;
  PipelineOptions opt = test::test_options();
  opt.max_frames = 120;
  opt.pacing = pacing;
  opt.trigger_rate_hz = rate_hz;
  opt.blob_tap = &tap;
  opt.every_frame = true;
  auto p = Pipeline::create(rig.processor(), rig.cameras(), {}, opt);
  ASSERT_TRUE(p.ok()) << p.error().message;
  ASSERT_TRUE((*p)->start().ok());
  test::wait_finished(**p);
  (*p)->stop();
  const PipelineStats st = (*p)->stats();
  for (std::size_t c = 0; c < 2; ++c) {
    const std::string k = std::to_string(c);
    EXPECT_EQ(test::counter(st, "detect" + k + "_skipped"), 0u);
    const std::uint64_t delivered = rig.cams[c]->counters().frames.get();
    EXPECT_EQ(tap.count[c] + test::counter(st, "capture_dropped_cam" + k) +
                  test::counter(st, "detect" + k + "_no_slot"),
              delivered)
        << "camera " << c;
    if (pacing == TriggerPacing::kLockstep) {
      EXPECT_EQ(tap.count[c], 120u);
    }
    int with_blobs = 0;
    for (std::size_t i = 0; i < tap.count[c] && i < 256; ++i) {
      if (i > 0) {
        EXPECT_GT(tap.sequence[c][i], tap.sequence[c][i - 1]);  // in order
      }
      with_blobs += tap.blob_count[c][i] > 0 ? 1 : 0;
    }
    EXPECT_GT(with_blobs, static_cast<int>(tap.count[c]) / 2);
  }
}

TEST(BlobTap, LockstepHandsEveryFrameToTheTapInOrder) {
  run_with_tap(TriggerPacing::kLockstep, 100.0);
}

TEST(BlobTap, PeriodicDetectsEveryFrameOrCountsItsDrop) {
  run_with_tap(TriggerPacing::kPeriodic, 400.0);
}

}  // namespace
}  // namespace mocap::pipeline
