// Design: fuzz entry point of the blob detector on arbitrary images. A 6-byte prefix
// chooses the image (width, height 1..96, 8/16-bit, maxval) and the configuration
// (fixed or adaptive threshold, small max_blobs/max_runs so overflow paths are hit,
// ROI, split and ring options); the remaining bytes are the pixels (repeated to fill
// the image). Properties: detect() never writes past the BlobList, every blob is finite
// and inside the image, and overflow is counted rather than overrun.
#include <cmath>
#include <cstdio>
#include <cstring>

#include "core/image.h"
#include "detect/blob_detector.h"
#include "tests/fuzz/fuzz_targets.h"

namespace mocap::fuzz {

int fuzz_blob_detector(const std::uint8_t* data, std::size_t size) {
  using namespace mocap::detect;
  if (size < 7) return 0;
  const int width = 1 + data[0] % 96;
  const int height = 1 + data[1] % 96;
  const bool wide = (data[2] & 1u) != 0;
  DetectorConfig cfg;
  cfg.threshold_mode = (data[2] & 2u) ? ThresholdMode::kFixed : ThresholdMode::kAdaptive;
  cfg.split_merged = (data[2] & 4u) != 0;
  cfg.centroid_ring = (data[2] & 8u) != 0;
  cfg.border = (data[2] & 16u) ? BorderPolicy::kReject : BorderPolicy::kFlag;
  cfg.simd = (data[2] & 32u) ? SimdLevel::kScalar : SimdLevel::kAuto;
  if (data[2] & 64u) cfg.roi = Roi{width / 4, height / 4, width / 2, height / 2};
  cfg.max_blobs = 1 + data[3] % 16;
  cfg.max_runs = 1 + (data[4] % 64) * 8;
  cfg.min_area_px = 1 + data[5] % 4;
  cfg.background_sample_step_px = 1 + data[5] % 8;
  const std::uint16_t maxval = wide ? static_cast<std::uint16_t>(256 + data[6] * 251) : 255;
  cfg.threshold_dn = wide ? 1 + data[6] * 200 : 1 + data[6];
  cfg.max_area_px = width * height;
  if (cfg.roi.width == 0 || cfg.roi.height == 0) cfg.roi = Roi{};
  if (!validate_config(cfg, width, height)) return 0;
  auto det = BlobDetector::create(cfg, width, height);
  if (!det) return 0;

  Image img(width, height, wide ? PixelFormat::kMono16 : PixelFormat::kMono8, maxval);
  const std::uint8_t* px = data + 7;
  const std::size_t n_px = size - 7;
  for (std::size_t i = 0; i < img.size_bytes(); ++i) img.data()[i] = n_px ? px[i % n_px] : 0;
  if (wide) {  // keep samples within maxval, as a valid PGM guarantees
    for (int y = 0; y < height; ++y) {
      std::uint16_t* row = img.row16(y);
      for (int x = 0; x < width; ++x) row[x] = static_cast<std::uint16_t>(row[x] % (maxval + 1u));
    }
  }

  BlobList blobs = det->make_blob_list();
  for (int pass = 0; pass < 2; ++pass) {  // twice: per-frame state must reset cleanly
    det->detect(img.view(), blobs);
    fuzz_check(blobs.size() <= blobs.capacity(), "blob list overrun");
    for (const Blob& b : blobs) {
      fuzz_check(std::isfinite(b.x_px) && std::isfinite(b.y_px), "non-finite centroid");
      if (!(b.x_px >= -0.5 && b.x_px <= width - 0.5 && b.y_px >= -0.5 && b.y_px <= height - 0.5)) {
        std::fprintf(stderr, "blob (%g, %g) bbox [%d..%d]x[%d..%d] flags %u area %g in %dx%d\n",
                     b.x_px, b.y_px, b.x_min, b.x_max, b.y_min, b.y_max, b.flags,
                     static_cast<double>(b.area_px), width, height);
        fuzz_check_failed("centroid outside the image");
      }
      fuzz_check(b.x_min >= 0 && b.y_min >= 0 && b.x_max < width && b.y_max < height &&
                     b.x_min <= b.x_max && b.y_min <= b.y_max,
                 "bounding box outside the image");
    }
  }
  // A frame of the wrong size is refused, not read.
  Image small(width + 1, height, PixelFormat::kMono8, 255);
  fuzz_check(!det->detect(small.view(), blobs) && blobs.empty(),
             "frame of the wrong size accepted");
  const DetectorCounters& c = det->counters();
  fuzz_check(c.frames == 3 && c.frames_invalid == 1, "frames not counted");
  return 0;
}

}  // namespace mocap::fuzz
