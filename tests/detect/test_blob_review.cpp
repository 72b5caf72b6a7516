// Tests of detect::review_blobs / recommend / draw_blob_overlay (`mocap preview`): every
// rejection reason of the configured thresholds on a drawn image, the recommendation's
// priorities and the overlay's marks.
#include <gtest/gtest.h>

#include <cmath>

#include "detect/blob_review.h"

namespace mocap::detect {
namespace {

constexpr int kW = 200, kH = 150;

void disc(Image& im, double cx, double cy, double r, std::uint8_t v) {
  for (int y = 0; y < kH; ++y)
    for (int x = 0; x < kW; ++x)
      if (std::hypot(x - cx, y - cy) <= r) im.row8(y)[x] = v;
}
void rect(Image& im, int x0, int y0, int x1, int y1, std::uint8_t v) {
  for (int y = y0; y <= y1; ++y)
    for (int x = x0; x <= x1; ++x) im.row8(y)[x] = v;
}

DetectorConfig config() {
  DetectorConfig c;
  c.threshold_mode = ThresholdMode::kFixed;
  c.threshold_dn = 40;
  c.background_dn = 10;
  c.min_area_px = 4;
  c.max_area_px = 1000;
  c.max_elongation = 2.0;
  c.split_merged = false;
  c.border = BorderPolicy::kReject;
  return c;
}

Image scene(bool with_saturated) {
  Image im(kW, kH, PixelFormat::kMono8, 255);
  rect(im, 0, 0, kW - 1, kH - 1, 10);
  rect(im, 20, 20, 21, 20, 200);     // speck: too small
  disc(im, 60.3, 60.6, 4.0, 180);    // a good marker
  rect(im, 120, 90, 179, 129, 150);  // glare: too large
  rect(im, 20, 100, 39, 102, 200);   // bar: elongated
  disc(im, 0.0, 75.0, 4.0, 180);     // cut by the border
  if (with_saturated) disc(im, 100.0, 30.0, 4.0, 255);
  return im;
}

TEST(BlobReview, JudgesEveryComponentAgainstTheConfiguredThresholds) {
  const Image im = scene(true);
  auto r = review_blobs(config(), im.view());
  ASSERT_TRUE(r) << r.error().message;
  EXPECT_EQ(r->accepted, 2);
  EXPECT_EQ(r->rejected[static_cast<int>(BlobVerdict::kTooSmall)], 1);
  EXPECT_EQ(r->rejected[static_cast<int>(BlobVerdict::kTooLarge)], 1);
  EXPECT_EQ(r->rejected[static_cast<int>(BlobVerdict::kElongated)], 1);
  EXPECT_EQ(r->rejected[static_cast<int>(BlobVerdict::kBorder)], 1);
  EXPECT_EQ(r->saturated, 1);
  EXPECT_EQ(r->image_peak_dn, 255);
  EXPECT_EQ(r->threshold_dn, 40u);
  bool found = false;
  for (const ReviewedBlob& b : r->blobs) {
    if (b.verdict == BlobVerdict::kAccepted && std::abs(b.blob.x_px - 60.3) < 0.5) {
      found = true;
      EXPECT_NEAR(b.blob.y_px, 60.6, 0.5);
      EXPECT_EQ(b.blob.peak_dn, 180);
    }
  }
  EXPECT_TRUE(found);
  // The detector itself (configured limits) accepts exactly the accepted ones.
  EXPECT_NE(recommend(*r).find("saturated, lower exposure"), std::string::npos) << recommend(*r);
}

TEST(BlobReview, RecommendationFollowsTheMostImportantProblem) {
  auto glare = review_blobs(config(), scene(false).view());
  ASSERT_TRUE(glare);
  EXPECT_NE(recommend(*glare).find("larger than max_area_px 1000"), std::string::npos)
      << recommend(*glare);
  Image dark(kW, kH, PixelFormat::kMono8, 255);
  rect(dark, 0, 0, kW - 1, kH - 1, 10);
  auto none = review_blobs(config(), dark.view());
  ASSERT_TRUE(none);
  EXPECT_NE(recommend(*none).find("no blob above the threshold 40"), std::string::npos);
  Image good(kW, kH, PixelFormat::kMono8, 255);
  rect(good, 0, 0, kW - 1, kH - 1, 10);
  disc(good, 50, 50, 4, 200);
  disc(good, 120, 80, 5, 210);
  auto ok = review_blobs(config(), good.view());
  ASSERT_TRUE(ok);
  EXPECT_EQ(recommend(*ok).rfind("OK: 2 markers, peak 210 of 255", 0), 0u) << recommend(*ok);
  Image dim = good;
  rect(dim, 0, 0, kW - 1, kH - 1, 10);
  disc(dim, 50, 50, 4, 60);
  auto low = review_blobs(config(), dim.view());
  ASSERT_TRUE(low);
  EXPECT_NE(recommend(*low).find("dim, raise exposure"), std::string::npos) << recommend(*low);
}

TEST(BlobReview, OverlayMarksCentroidsAndReasons) {
  const Image im = scene(true);
  auto r = review_blobs(config(), im.view());
  ASSERT_TRUE(r);
  const RgbImage png = draw_blob_overlay(im.view(), *r);
  ASSERT_EQ(png.width, kW);
  ASSERT_EQ(png.height, kH);
  auto at = [&](int x, int y) {
    const std::size_t i = (static_cast<std::size_t>(y) * kW + static_cast<std::size_t>(x)) * 3;
    return std::array<int, 3>{png.rgb[i], png.rgb[i + 1], png.rgb[i + 2]};
  };
  EXPECT_EQ(at(60, 61), (std::array<int, 3>{255, 0, 0}));  // centroid cross
  EXPECT_EQ(at(60, 61 - 3), (std::array<int, 3>{255, 0, 0}));
  EXPECT_EQ(at(2, 2), (std::array<int, 3>{10, 10, 10}));  // background stays grey
  // The glare's box (too large: orange) around 120..179 x 90..129.
  EXPECT_EQ(at(150, 88), (std::array<int, 3>{255, 120, 0}));
  // The speck's "S" glyph right of its box in yellow.
  bool yellow = false;
  for (int y = 16; y < 30; ++y)
    for (int x = 25; x < 32; ++x) yellow |= at(x, y) == std::array<int, 3>{255, 220, 0};
  EXPECT_TRUE(yellow);
}

TEST(BlobReview, RejectsBadInputWithOneLine) {
  DetectorConfig bad = config();
  bad.min_area_px = 0;
  const Image im = scene(false);
  auto r = review_blobs(bad, im.view());
  ASSERT_FALSE(r);
  EXPECT_NE(r.error().message.find("min_area_px"), std::string::npos);
  EXPECT_FALSE(review_blobs(config(), ImageView{}));
}

}  // namespace
}  // namespace mocap::detect
