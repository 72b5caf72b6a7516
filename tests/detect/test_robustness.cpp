// Design: the detector under hostile input and its real-time guarantees: capacity
// overflow (blobs and runs) is counted and never written past; damaged frames never
// crash; every SIMD kernel yields exactly the scalar result; steady-state detection
// allocates nothing; bad configurations are refused with a one-line error.
#include <cstring>
#include <random>

#include "tests/detect/test_util.h"
#include "tests/support/alloc_counter.h"

namespace mocap::detect::test {
namespace {

// A grid of 3x3 bright squares every 6 px (a frame "full of blobs").
SynthImage grid_image(int w, int h, PixelFormat f = PixelFormat::kMono8) {
  SynthParams p;
  p.width = w;
  p.height = h;
  p.format = f;
  p.maxval = f == PixelFormat::kMono8 ? 255 : 65535;
  p.noise_sigma_dn = 0.0;
  SynthImage im = render({}, p);
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      if (y % 6 >= 2 && y % 6 < 5 && x % 6 >= 2 && x % 6 < 5) {
        std::uint8_t* row = im.bytes.data() + static_cast<std::size_t>(y) * im.view.stride_bytes;
        if (f == PixelFormat::kMono8) {
          row[x] = 220;
        } else {
          reinterpret_cast<std::uint16_t*>(row)[x] = 50000;
        }
      }
    }
  }
  return im;
}

TEST(DetectRobustness, BlobCapacityOverflowIsCounted) {
  const SynthImage im = grid_image(240, 180);  // 40 x 30 = 1200 squares
  DetectorConfig cfg;
  cfg.min_area_px = 4;
  cfg.max_blobs = 100;
  BlobDetector det = make_detector(cfg, 240, 180);
  BlobList blobs = det.make_blob_list();
  EXPECT_FALSE(det.detect(im.view, blobs));
  EXPECT_EQ(blobs.size(), 100u);
  EXPECT_EQ(blobs.capacity(), 100u);
  EXPECT_EQ(det.counters().blobs_dropped, 1100u);
  EXPECT_EQ(det.counters().frames_overflow, 1u);
  EXPECT_EQ(det.counters().last_components, 1200u);
  // A caller's smaller list is respected as well.
  BlobList small(7);
  EXPECT_FALSE(det.detect(im.view, small));
  EXPECT_EQ(small.size(), 7u);
}

TEST(DetectRobustness, RunCapacityOverflowStopsTheScan) {
  const SynthImage im = grid_image(240, 180);  // 40 runs per bright row, 90 bright rows
  DetectorConfig cfg;
  cfg.max_runs = 500;
  BlobDetector det = make_detector(cfg, 240, 180);
  BlobList blobs = det.make_blob_list();
  EXPECT_FALSE(det.detect(im.view, blobs));
  EXPECT_EQ(det.counters().runs_overflow, 1u);
  EXPECT_EQ(det.counters().last_runs, 500u);
  // Squares completed before the overflow row are reported; the cut ones are flagged.
  EXPECT_GT(blobs.size(), 100u);
  for (const Blob& b : blobs) {
    if (!b.has(kBlobTruncated)) {
      EXPECT_FLOAT_EQ(b.area_px, 9.0f);
    }
  }
}

TEST(DetectRobustness, DamagedFramesNeverCrash) {
  std::mt19937 rng(3);
  for (PixelFormat f : {PixelFormat::kMono8, PixelFormat::kMono16}) {
    const std::uint16_t maxval = f == PixelFormat::kMono8 ? 255 : 65535;
    for (auto [w, h] : {std::pair{1, 1}, {1, 300}, {300, 1}, {2, 2}, {33, 17}, {640, 480}}) {
      DetectorConfig cfg;
      cfg.max_runs = 4096;
      BlobDetector det = make_detector(cfg, w, h);
      BlobList blobs = det.make_blob_list();
      const int bpp = bytes_per_pixel(f);
      std::vector<std::uint8_t> buf(static_cast<std::size_t>(w) * h * bpp);
      ImageView v{buf.data(), w, h, w * bpp, f, maxval};
      // All black, all white, speckle (salt and pepper), uniform random.
      for (int kind = 0; kind < 4; ++kind) {
        for (std::size_t i = 0; i < buf.size(); ++i) {
          const auto r = rng();
          buf[i] = kind == 0   ? 0
                   : kind == 1 ? 0xFF
                   : kind == 2 ? ((r & 1) ? 0xFF : 0)
                               : static_cast<std::uint8_t>(r);
        }
        (void)det.detect(v, blobs);
        EXPECT_LE(blobs.size(), blobs.capacity());
        if (kind == 1 && w * h > 4) {
          EXPECT_EQ(blobs.size(), 0u);  // all white: no marker
        }
      }
      // Wrong size and null data are refused and counted.
      ImageView wrong{buf.data(), w + 1, h, (w + 1) * bpp, f, maxval};
      EXPECT_FALSE(det.detect(wrong, blobs));
      ImageView null_view{nullptr, w, h, w * bpp, f, maxval};
      EXPECT_FALSE(det.detect(null_view, blobs));
      EXPECT_EQ(blobs.size(), 0u);
      EXPECT_EQ(det.counters().frames_invalid, 2u);
    }
  }
}

// Random scenes (bright shapes, noise, odd widths, padded strides, ROIs): every SIMD
// level must give bit-identical blobs to the scalar kernel.
TEST(DetectRobustness, SimdEqualsScalarExactly) {
  std::mt19937 rng(11);
  int compared = 0;
  for (int trial = 0; trial < 60; ++trial) {
    SynthParams p;
    p.width = 1 + static_cast<int>(rng() % 300);
    p.height = 1 + static_cast<int>(rng() % 120);
    p.format = trial % 2 == 0 ? PixelFormat::kMono8 : PixelFormat::kMono16;
    p.maxval = p.format == PixelFormat::kMono8 ? 255 : (trial % 4 == 1 ? 65535 : 4095);
    const double scale = p.maxval / 255.0;
    p.background_dn = 20.0 * scale;
    p.noise_sigma_dn = (trial % 3) * 3.0 * scale;
    p.stride_pad_bytes = static_cast<int>(rng() % 3) * 2;
    p.seed = static_cast<std::uint32_t>(trial);
    const auto spots = random_discs(static_cast<int>(rng() % 40), p, 0.7, 6.0, 30.0 * scale,
                                    300.0 * scale, -3.0, p.seed, 0);
    const SynthImage im = render(spots, p);
    DetectorConfig cfg;
    cfg.min_area_px = 1;
    cfg.min_contrast_dn = static_cast<int>(8 * scale);
    if (trial % 5 == 4 && p.width > 10 && p.height > 10) {
      cfg.roi =
          Roi{static_cast<int>(rng() % 5), static_cast<int>(rng() % 5), p.width - 7, p.height - 8};
    }
    std::vector<BlobList> results;
    std::vector<DetectorCounters> counters;
    for (SimdLevel level : {SimdLevel::kScalar, SimdLevel::kSse2, SimdLevel::kAvx2}) {
      cfg.simd = level;
      BlobDetector det = make_detector(cfg, p.width, p.height);
      BlobList blobs = det.make_blob_list();
      (void)det.detect(im.view, blobs);
      results.push_back(blobs);
      counters.push_back(det.counters());
    }
    for (std::size_t k = 1; k < results.size(); ++k) {
      ASSERT_EQ(results[k].size(), results[0].size()) << "trial " << trial;
      EXPECT_EQ(counters[k].last_runs, counters[0].last_runs);
      for (std::size_t i = 0; i < results[0].size(); ++i) {
        EXPECT_TRUE(same_blob(results[k][i], results[0][i])) << "trial " << trial << " blob " << i;
      }
    }
    compared += static_cast<int>(results[0].size());
  }
  EXPECT_GT(compared, 300);
  BlobDetector best = make_detector(DetectorConfig{}, 8, 8);
  std::printf("[simd] auto-selected level: %s\n", simd_level_name(best.simd_level()));
}

TEST(DetectRobustness, ZeroAllocationsPerFrame) {
  for (PixelFormat f : {PixelFormat::kMono8, PixelFormat::kMono16}) {
    SynthParams p;
    p.width = 640;
    p.height = 480;
    p.format = f;
    p.maxval = f == PixelFormat::kMono8 ? 255 : 65535;
    const double scale = p.maxval / 255.0;
    p.background_dn = 20 * scale;
    p.noise_sigma_dn = 2 * scale;
    auto spots = random_discs(40, p, 3.0, 8.0, 180 * scale, 230 * scale, 3.0, 9u);
    spots.push_back({300.0, 200.0, 5.0, 200 * scale});  // a merged pair -> split path
    spots.push_back({308.0, 200.0, 5.0, 200 * scale});
    const SynthImage im = render(spots, p);
    const SynthImage grid = grid_image(640, 480, f);
    DetectorConfig cfg;
    cfg.min_contrast_dn = static_cast<int>(12 * scale);
    cfg.max_runs = 2000;
    BlobDetector det = make_detector(cfg, p.width, p.height);
    BlobList blobs = det.make_blob_list();
    (void)det.detect(im.view, blobs);
    mocap::test::AllocationScope scope;
    for (int i = 0; i < 20; ++i) {
      (void)det.detect(im.view, blobs);
      (void)det.detect(grid.view, blobs);  // overflow path too
    }
    EXPECT_EQ(scope.count(), 0u);
    EXPECT_GE(det.counters().splits, 1u);
  }
}

TEST(DetectRobustness, BadConfigIsRefusedWithOneLineError) {
  auto expect_error = [](DetectorConfig c, const std::string& key, int w = 640, int h = 480) {
    auto d = BlobDetector::create(c, w, h);
    ASSERT_FALSE(d.ok()) << key;
    EXPECT_EQ(d.error().message.find('\n'), std::string::npos);
    EXPECT_EQ(d.error().message.rfind("detector: " + key + ":", 0), 0u) << d.error().message;
  };
  DetectorConfig c;
  expect_error(c, "width", 0, 10);
  expect_error(c, "height", 10, -1);
  c = {};
  c.min_area_px = 0;
  expect_error(c, "min_area_px");
  c = {};
  c.max_area_px = 2;
  expect_error(c, "max_area_px");
  c = {};
  c.max_elongation = 0.5;
  expect_error(c, "max_elongation");
  c = {};
  c.roi = Roi{600, 0, 100, 10};
  expect_error(c, "roi");
  c = {};
  c.roi = Roi{0, 0, 100, 0};
  expect_error(c, "roi");
  c = {};
  c.max_blobs = 0;
  expect_error(c, "max_blobs");
  c = {};
  c.max_runs = 0;
  expect_error(c, "max_runs");
  c = {};
  c.threshold_sigma = -1;
  expect_error(c, "threshold_sigma");
  c = {};
  c.merge_saddle_ratio = 0;
  expect_error(c, "merge_saddle_ratio");
  c = {};
  c.threshold_mode = ThresholdMode::kFixed;
  c.threshold_dn = 0;
  expect_error(c, "threshold_dn");
  c = {};
  c.threshold_mode = ThresholdMode::kFixed;
  c.background_dn = 50;
  c.threshold_dn = 40;
  expect_error(c, "background_dn");
  EXPECT_TRUE(BlobDetector::create(DetectorConfig{}, 640, 480).ok());
}

}  // namespace
}  // namespace mocap::detect::test
