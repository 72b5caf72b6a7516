// Design: the detector's two scan strategies (blob_detector.h) against each other, and
// the chunk-maximum kernels (chunk_max.h) against a plain loop. The two-pass scan reads
// runs only in 128-byte chunks whose maximum reaches the threshold; it must give
// bit-identical blobs, counters and image levels to the full reference scan on every
// scene: widths that are and are not multiples of a chunk, ROIs starting mid-chunk,
// padded strides, 8- and 16-bit (12-bit and full range), adaptive and fixed thresholds,
// markers straddling chunk boundaries, run overflow, and damaged frames.
#include <random>

#include "detect/chunk_max.h"
#include "tests/detect/test_util.h"

namespace mocap::detect::test {
namespace {

struct ScanResult {
  bool ok = false;
  BlobList blobs;
  DetectorCounters counters{};
};

ScanResult run_scan(DetectorConfig cfg, bool full_scan, const ImageView& view) {
  cfg.full_scan = full_scan;
  BlobDetector det = make_detector(cfg, view.width, view.height);
  ScanResult r;
  r.blobs = det.make_blob_list();
  r.ok = det.detect(view, r.blobs);
  r.counters = det.counters();
  return r;
}

void expect_same_scan(const DetectorConfig& cfg, const ImageView& view, const char* what) {
  const ScanResult ref = run_scan(cfg, true, view);
  const ScanResult two = run_scan(cfg, false, view);
  EXPECT_EQ(two.ok, ref.ok) << what;
  ASSERT_EQ(two.blobs.size(), ref.blobs.size()) << what;
  for (std::size_t i = 0; i < ref.blobs.size(); ++i)
    EXPECT_TRUE(same_blob(two.blobs[i], ref.blobs[i])) << what << " blob " << i;
  EXPECT_EQ(two.counters.last_runs, ref.counters.last_runs) << what;
  EXPECT_EQ(two.counters.last_components, ref.counters.last_components) << what;
  EXPECT_EQ(two.counters.runs_overflow, ref.counters.runs_overflow) << what;
  EXPECT_EQ(two.counters.frames_no_contrast, ref.counters.frames_no_contrast) << what;
  EXPECT_EQ(two.counters.last_threshold_dn, ref.counters.last_threshold_dn) << what;
  EXPECT_EQ(two.counters.last_background_dn, ref.counters.last_background_dn) << what;
  EXPECT_EQ(two.counters.last_noise_dn, ref.counters.last_noise_dn) << what;
  EXPECT_EQ(two.blobs.levels().threshold_dn, ref.blobs.levels().threshold_dn) << what;
}

TEST(DetectScan, TwoPassEqualsFullScanOnRandomScenes) {
  std::mt19937 rng(29);
  int compared = 0;
  for (int trial = 0; trial < 80; ++trial) {
    SynthParams p;
    // Around and across chunk sizes (128 px at 8 bit, 64 px at 16 bit).
    p.width = 1 + static_cast<int>(rng() % 700);
    p.height = 1 + static_cast<int>(rng() % 160);
    p.format = trial % 2 == 0 ? PixelFormat::kMono8 : PixelFormat::kMono16;
    p.maxval = p.format == PixelFormat::kMono8 ? 255 : (trial % 4 == 1 ? 65535 : 4095);
    const double scale = p.maxval / 255.0;
    p.background_dn = (5.0 + static_cast<double>(static_cast<int>(rng() % 40))) * scale;
    p.noise_sigma_dn = (trial % 3) * 3.0 * scale;
    p.blur_sigma_px = trial % 3 == 0 ? 0.6 : 0.0;
    p.stride_pad_bytes = static_cast<int>(rng() % 4) * 2;
    p.seed = static_cast<std::uint32_t>(100 + trial);
    const auto spots = random_discs(static_cast<int>(rng() % 60), p, 0.7, 9.0, 20.0 * scale,
                                    300.0 * scale, -3.0, p.seed, 0);
    const SynthImage im = render(spots, p);
    DetectorConfig cfg;
    cfg.min_area_px = 1;
    cfg.min_contrast_dn = static_cast<int>(8 * scale);
    if (trial % 3 == 1) {
      cfg.threshold_mode = ThresholdMode::kFixed;
      cfg.threshold_dn =
          static_cast<int>(static_cast<double>(40 + static_cast<int>(rng() % 60)) * scale);
    }
    if (trial % 4 == 3 && p.width > 20 && p.height > 10) {  // ROIs starting mid-chunk
      const int x = static_cast<int>(rng() % 13), y = static_cast<int>(rng() % 5);
      cfg.roi = Roi{x, y, p.width - x - static_cast<int>(rng() % 7), p.height - y - 3};
    }
    expect_same_scan(cfg, im.view, ("trial " + std::to_string(trial)).c_str());
    compared += static_cast<int>(run_scan(cfg, false, im.view).blobs.size());
  }
  EXPECT_GT(compared, 500);
}

// Markers centred on chunk boundaries (a run split across two bright chunks) and in
// the last, short chunk of a row.
TEST(DetectScan, MarkersOnChunkBoundaries) {
  for (PixelFormat f : {PixelFormat::kMono8, PixelFormat::kMono16}) {
    SynthParams p;
    p.width = 517;
    p.height = 90;
    p.format = f;
    p.maxval = f == PixelFormat::kMono8 ? 255 : 4095;
    const double scale = p.maxval / 255.0;
    p.background_dn = 15 * scale;
    p.noise_sigma_dn = 2 * scale;
    const int chunk = f == PixelFormat::kMono8 ? kChunkPx8 : kChunkPx16;
    std::vector<Spot> spots;
    for (int k = 1; k * chunk < p.width; ++k)
      spots.push_back({k * chunk - 0.5, 20.0 + 25.0 * (k % 3), 4.0, 180 * scale});
    spots.push_back({p.width - 3.0, 60.0, 2.5, 150 * scale});
    const SynthImage im = render(spots, p);
    DetectorConfig cfg;
    cfg.min_area_px = 1;
    expect_same_scan(cfg, im.view, f == PixelFormat::kMono8 ? "8-bit" : "16-bit");
    const ScanResult two = run_scan(cfg, false, im.view);
    const MatchStats m = match(spots, two.blobs, 0.5);
    EXPECT_EQ(m.matched, static_cast<int>(spots.size()));
  }
}

// A frame full of blobs overflows the run buffer at the same row either way.
TEST(DetectScan, RunOverflowAtTheSameRow) {
  SynthParams p;
  p.width = 300;
  p.height = 200;
  p.noise_sigma_dn = 0.0;
  std::vector<Spot> spots;
  for (int y = 4; y < p.height - 4; y += 6)
    for (int x = 4; x < p.width - 4; x += 6) spots.push_back({x + 0.0, y + 0.0, 1.6, 200.0});
  const SynthImage im = render(spots, p);
  DetectorConfig cfg;
  cfg.min_area_px = 1;
  cfg.max_runs = 700;
  expect_same_scan(cfg, im.view, "overflow");
  EXPECT_EQ(run_scan(cfg, false, im.view).counters.runs_overflow, 1u);
}

// Uniform, saturated and random frames: the same (lack of) result either way.
TEST(DetectScan, DamagedFramesGiveTheSameResult) {
  std::mt19937 rng(5);
  for (PixelFormat f : {PixelFormat::kMono8, PixelFormat::kMono16}) {
    const int w = 333, h = 47, bpp = bytes_per_pixel(f);
    std::vector<std::uint8_t> buf(static_cast<std::size_t>(w) * h * bpp);
    const ImageView v{
        buf.data(), w, h,
        w * bpp,    f, static_cast<std::uint16_t>(f == PixelFormat::kMono8 ? 255 : 65535)};
    for (int kind = 0; kind < 4; ++kind) {
      for (std::uint8_t& b : buf) {
        const auto r = rng();
        b = kind == 0   ? 0
            : kind == 1 ? 0xFF
            : kind == 2 ? ((r & 1) ? 0xFF : 0)
                        : static_cast<std::uint8_t>(r);
      }
      DetectorConfig cfg;
      cfg.max_runs = 4096;
      expect_same_scan(cfg, v, ("kind " + std::to_string(kind)).c_str());
    }
  }
}

template <class T>
std::vector<std::uint16_t> plain_maxima(const std::vector<T>& row, int x0, int x1, int chunk,
                                        std::uint16_t& row_max) {
  std::vector<std::uint16_t> out;
  row_max = 0;
  for (int x = x0; x < x1; x += chunk) {
    std::uint16_t m = 0;
    for (int i = x; i < std::min(x + chunk, x1); ++i) m = std::max<std::uint16_t>(m, row[i]);
    out.push_back(m);
    row_max = std::max(row_max, m);
  }
  return out;
}

// Every kernel gives the exact maxima of a plain loop, for every span [x0, x1) of a
// row, and reads nothing outside it (ASan: the row is allocated to its exact size).
TEST(DetectScan, ChunkMaxKernelsAreExact) {
  std::mt19937 rng(8);
  for (SimdLevel level : {SimdLevel::kScalar, SimdLevel::kAvx2}) {
    const ChunkMaxKernels k = select_chunk_max_kernels(level);
    for (int trial = 0; trial < 400; ++trial) {
      const int n = 1 + static_cast<int>(rng() % 900);
      const int x0 = static_cast<int>(rng() % static_cast<unsigned>(n));
      const int x1 = x0 + 1 + static_cast<int>(rng() % static_cast<unsigned>(n - x0));
      std::vector<std::uint8_t> r8(static_cast<std::size_t>(n));
      std::vector<std::uint16_t> r16(static_cast<std::size_t>(n));
      for (int i = 0; i < n; ++i) {
        // Mostly dark with rare peaks (one peak per chunk tests each lane position).
        const auto v = rng();
        r8[i] = static_cast<std::uint8_t>(v % 7 == 0 ? v >> 8 : v % 16);
        r16[i] = static_cast<std::uint16_t>(v % 7 == 0 ? v >> 8 : v % 16);
      }
      std::uint16_t want_max8 = 0, want_max16 = 0;
      const auto want8 = plain_maxima(r8, x0, x1, kChunkPx8, want_max8);
      const auto want16 = plain_maxima(r16, x0, x1, kChunkPx16, want_max16);
      std::vector<std::uint16_t> got8(want8.size() + 1, 0xBEEF), got16(want16.size() + 1, 0xBEEF);
      EXPECT_EQ(k.k8(r8.data(), x0, x1, got8.data()), want_max8);
      EXPECT_EQ(k.k16(r16.data(), x0, x1, got16.data()), want_max16);
      EXPECT_EQ(got8.back(), 0xBEEF);  // nothing written past the last chunk
      EXPECT_EQ(got16.back(), 0xBEEF);
      got8.pop_back();
      got16.pop_back();
      EXPECT_EQ(got8, want8) << "n " << n << " [" << x0 << ", " << x1 << ")";
      EXPECT_EQ(got16, want16) << "n " << n << " [" << x0 << ", " << x1 << ")";
    }
  }
}

}  // namespace
}  // namespace mocap::detect::test
