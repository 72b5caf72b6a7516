// Design: per-blob measurements and the decisions built on them: area, bounding box,
// peak, roundness/orientation; rejection by size and elongation; border flag and
// policy; merged-marker flag and split; region of interest; fixed threshold mode.
#include <cmath>
#include <cstdio>
#include <numbers>

#include "tests/detect/test_util.h"

namespace mocap::detect::test {
namespace {

SynthParams quiet(int w = 200, int h = 150) {
  SynthParams p;
  p.width = w;
  p.height = h;
  p.noise_sigma_dn = 0.0;
  return p;
}

TEST(DetectShape, AreaBboxPeakRoundness) {
  SynthParams p = quiet();
  p.noise_sigma_dn = 1.0;
  const Spot s{80.3, 60.7, 6.0, 200.0};
  const SynthImage im = render({s}, p);
  BlobDetector det = make_detector(DetectorConfig{}, p.width, p.height);
  BlobList blobs = det.make_blob_list();
  ASSERT_TRUE(det.detect(im.view, blobs));
  ASSERT_EQ(blobs.size(), 1u);
  const Blob& b = blobs[0];
  // Area and bounding box are those of the pixels at or above the frame's threshold.
  const int thr = static_cast<int>(det.counters().last_threshold_dn);
  int area = 0, x0 = 1 << 30, x1 = -1, y0 = 1 << 30, y1 = -1;
  for (int y = 0; y < p.height; ++y) {
    for (int x = 0; x < p.width; ++x) {
      if (im.view.row8(y)[x] >= thr) {
        ++area;
        x0 = std::min(x0, x);
        x1 = std::max(x1, x);
        y0 = std::min(y0, y);
        y1 = std::max(y1, y);
      }
    }
  }
  EXPECT_EQ(b.area_px, static_cast<float>(area));
  EXPECT_EQ(b.x_min, x0);
  EXPECT_EQ(b.x_max, x1);
  EXPECT_EQ(b.y_min, y0);
  EXPECT_EQ(b.y_max, y1);
  // Threshold ~6% of the amplitude: between the disc and the disc grown by a pixel.
  EXPECT_GT(b.area_px, std::numbers::pi * 36.0);
  EXPECT_LT(b.area_px, std::numbers::pi * 49.0);
  // The peak is the brightest pixel.
  std::uint16_t peak = 0;
  for (int y = b.y_min; y <= b.y_max; ++y)
    for (int x = b.x_min; x <= b.x_max; ++x)
      peak = std::max<std::uint16_t>(peak, im.view.row8(y)[x]);
  EXPECT_EQ(b.peak_dn, peak);
  EXPECT_GT(b.roundness, 0.95f);
  EXPECT_LT(b.eccentricity, 0.3f);
  // Uniform disc: variance r^2/4 per axis -> axis 2*sqrt(r^2/4) = r (plus pixel term).
  EXPECT_NEAR(b.major_axis_px, 6.0, 0.4);
  EXPECT_FALSE(b.has(kBlobTouchesBorder));
  EXPECT_FALSE(b.has(kBlobMerged));
  EXPECT_EQ(b.background_dn, 20);
}

TEST(DetectShape, EllipseOrientationAndRoundness) {
  SynthParams p = quiet();
  const double angle = 0.5;
  const SynthImage im = render({Spot{100.0, 75.0, 10.0, 200.0, 0.5, angle}}, p);
  DetectorConfig cfg;
  cfg.split_merged = false;
  cfg.merge_elongation = 3.0;
  cfg.merge_elongation_no_saddle = 3.0;
  BlobDetector det = make_detector(cfg, p.width, p.height);
  BlobList blobs = det.make_blob_list();
  ASSERT_TRUE(det.detect(im.view, blobs));
  ASSERT_EQ(blobs.size(), 1u);
  EXPECT_NEAR(blobs[0].roundness, 0.5, 0.05);
  EXPECT_NEAR(blobs[0].orientation_rad, angle, 0.03);
  EXPECT_NEAR(blobs[0].x_px, 100.0, 0.02);
  EXPECT_NEAR(blobs[0].y_px, 75.0, 0.02);
}

TEST(DetectShape, RejectsBySizeAndElongation) {
  SynthParams p = quiet(300, 200);
  const std::vector<Spot> spots = {
      {30.0, 30.0, 0.5, 200.0},              // 1 px: too small
      {150.0, 100.0, 45.0, 200.0},           // ~6400 px: too large (max 2000 below)
      {40.0, 170.0, 20.0, 200.0, 0.1, 0.0},  // 40 x 4 px bar: elongation ~10
      {260.0, 40.0, 5.0, 200.0},             // the only good marker
  };
  const SynthImage im = render(spots, p);
  DetectorConfig cfg;
  cfg.max_area_px = 2000;
  cfg.merge_elongation_no_saddle = 20.0;  // the bar must not be taken for two markers
  BlobDetector det = make_detector(cfg, p.width, p.height);
  BlobList blobs = det.make_blob_list();
  ASSERT_TRUE(det.detect(im.view, blobs));
  ASSERT_EQ(blobs.size(), 1u);
  EXPECT_NEAR(blobs[0].x_px, 260.0, 0.05);
  EXPECT_EQ(det.counters().rejected_small, 1u);
  EXPECT_EQ(det.counters().rejected_large, 1u);
  EXPECT_EQ(det.counters().rejected_elongated, 1u);
}

TEST(DetectShape, BorderFlagAndRejectPolicy) {
  SynthParams p = quiet();
  const std::vector<Spot> spots = {
      {1.0, 40.0, 5.0, 200.0}, {100.0, 75.0, 5.0, 200.0}, {150.0, 148.0, 5.0, 200.0}};
  const SynthImage im = render(spots, p);
  DetectorConfig cfg;
  BlobDetector keep = make_detector(cfg, p.width, p.height);
  BlobList blobs = keep.make_blob_list();
  ASSERT_TRUE(keep.detect(im.view, blobs));
  ASSERT_EQ(blobs.size(), 3u);
  int flagged = 0;
  for (const Blob& b : blobs) flagged += b.has(kBlobTouchesBorder) ? 1 : 0;
  EXPECT_EQ(flagged, 2);
  cfg.border = BorderPolicy::kReject;
  BlobDetector reject = make_detector(cfg, p.width, p.height);
  ASSERT_TRUE(reject.detect(im.view, blobs));
  ASSERT_EQ(blobs.size(), 1u);
  EXPECT_NEAR(blobs[0].x_px, 100.0, 0.05);
  EXPECT_EQ(reject.counters().rejected_border, 2u);
}

// Two overlapping markers at several distances: flagged and split near the truth.
TEST(DetectShape, MergedPairIsFlaggedAndSplit) {
  SynthParams p = quiet();
  p.noise_sigma_dn = 2.0;
  for (double angle : {0.0, 0.7, 1.9}) {
    for (double dist : {7.0, 8.5, 10.0}) {  // radius 5: centre distance 1.4r .. 2r
      const double cx = 100.2, cy = 74.6;
      const double dx = 0.5 * dist * std::cos(angle), dy = 0.5 * dist * std::sin(angle);
      const std::vector<Spot> spots = {{cx - dx, cy - dy, 5.0, 200.0},
                                       {cx + dx, cy + dy, 5.0, 200.0}};
      const SynthImage im = render(spots, p);
      BlobDetector det = make_detector(DetectorConfig{}, p.width, p.height);
      BlobList blobs = det.make_blob_list();
      ASSERT_TRUE(det.detect(im.view, blobs));
      ASSERT_EQ(blobs.size(), 2u) << "angle " << angle << " dist " << dist;
      EXPECT_EQ(det.counters().merged, 1u);
      EXPECT_EQ(det.counters().splits, 1u);
      const MatchStats m = match(spots, blobs, 1.0);
      EXPECT_EQ(m.matched, 2);
      EXPECT_LE(m.max_px, 0.3) << "angle " << angle << " dist " << dist;
      std::printf("[split] angle=%.1f dist=%.1f px (r=5, clipped at 255): max error %.3f px\n",
                  angle, dist, m.max_px);
      for (const Blob& b : blobs) {
        EXPECT_TRUE(b.has(kBlobMerged));
        EXPECT_TRUE(b.has(kBlobSplit));
      }
    }
  }
}

TEST(DetectShape, MergedPairFlaggedOnlyWhenSplitDisabled) {
  SynthParams p = quiet();
  const std::vector<Spot> spots = {{95.0, 75.0, 5.0, 200.0}, {104.0, 75.0, 5.0, 200.0}};
  const SynthImage im = render(spots, p);
  DetectorConfig cfg;
  cfg.split_merged = false;
  BlobDetector det = make_detector(cfg, p.width, p.height);
  BlobList blobs = det.make_blob_list();
  ASSERT_TRUE(det.detect(im.view, blobs));
  ASSERT_EQ(blobs.size(), 1u);
  EXPECT_TRUE(blobs[0].has(kBlobMerged));
  EXPECT_FALSE(blobs[0].has(kBlobSplit));
  EXPECT_NEAR(blobs[0].x_px, 99.5, 0.1);
}

TEST(DetectShape, SingleRoundMarkersAreNotFlaggedMerged) {
  SynthParams p;
  p.width = 400;
  p.height = 300;
  const auto spots = random_discs(30, p, 3.0, 9.0, 150.0, 230.0, 4.0, 5u);
  const SynthImage im = render(spots, p);
  BlobDetector det = make_detector(DetectorConfig{}, p.width, p.height);
  BlobList blobs = det.make_blob_list();
  ASSERT_TRUE(det.detect(im.view, blobs));
  EXPECT_EQ(blobs.size(), spots.size());
  EXPECT_EQ(det.counters().merged, 0u);
}

TEST(DetectShape, RegionOfInterest) {
  SynthParams p = quiet();
  const std::vector<Spot> spots = {{30.0, 30.0, 5.0, 200.0}, {120.3, 80.6, 5.0, 200.0}};
  const SynthImage im = render(spots, p);
  DetectorConfig cfg;
  cfg.roi = Roi{90, 50, 70, 60};
  BlobDetector det = make_detector(cfg, p.width, p.height);
  BlobList blobs = det.make_blob_list();
  ASSERT_TRUE(det.detect(im.view, blobs));
  ASSERT_EQ(blobs.size(), 1u);
  EXPECT_NEAR(blobs[0].x_px, 120.3, 0.05);  // image coordinates, not ROI coordinates
  EXPECT_NEAR(blobs[0].y_px, 80.6, 0.05);
  EXPECT_FALSE(blobs[0].has(kBlobTouchesBorder));
  // A marker cut by the ROI edge is flagged like one cut by the image edge.
  cfg.roi = Roi{90, 50, 32, 60};
  BlobDetector cut = make_detector(cfg, p.width, p.height);
  ASSERT_TRUE(cut.detect(im.view, blobs));
  ASSERT_EQ(blobs.size(), 1u);
  EXPECT_TRUE(blobs[0].has(kBlobTouchesBorder));
  EXPECT_LE(blobs[0].x_max, 121);
}

TEST(DetectShape, FixedThresholdMode) {
  SynthParams p = quiet();
  p.background_dn = 10.0;
  const SynthImage im = render({Spot{60.4, 70.2, 6.0, 150.0}}, p);
  DetectorConfig cfg;
  cfg.threshold_mode = ThresholdMode::kFixed;
  cfg.threshold_dn = 40;
  cfg.background_dn = 10;
  BlobDetector det = make_detector(cfg, p.width, p.height);
  BlobList blobs = det.make_blob_list();
  ASSERT_TRUE(det.detect(im.view, blobs));
  ASSERT_EQ(blobs.size(), 1u);
  EXPECT_EQ(det.counters().last_threshold_dn, 40u);
  EXPECT_NEAR(blobs[0].x_px, 60.4, 0.01);
  EXPECT_NEAR(blobs[0].y_px, 70.2, 0.01);
  EXPECT_TRUE(blobs[0].has(kBlobSaturated) == false);
}

TEST(DetectShape, SaturatedFlag) {
  SynthParams p = quiet();
  const SynthImage im = render({Spot{60.0, 70.0, 6.0, 400.0}}, p);
  BlobDetector det = make_detector(DetectorConfig{}, p.width, p.height);
  BlobList blobs = det.make_blob_list();
  ASSERT_TRUE(det.detect(im.view, blobs));
  ASSERT_EQ(blobs.size(), 1u);
  EXPECT_TRUE(blobs[0].has(kBlobSaturated));
  EXPECT_EQ(blobs[0].peak_dn, 255);
}

}  // namespace
}  // namespace mocap::detect::test
