// Design: see blob_review.h.
#include "detect/blob_review.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "detect/blob_detector.h"

namespace mocap::detect {

const char* to_string(BlobVerdict v) noexcept {
  switch (v) {
    case BlobVerdict::kAccepted:
      return "accepted";
    case BlobVerdict::kTooSmall:
      return "too small";
    case BlobVerdict::kTooLarge:
      return "too large";
    case BlobVerdict::kBorder:
      return "touches the border";
    case BlobVerdict::kElongated:
      return "elongated";
  }
  return "?";
}

namespace {

std::uint16_t pixel(const ImageView& im, int x, int y) noexcept {
  return im.format == PixelFormat::kMono8 ? im.row8(y)[x] : im.row16(y)[x];
}

BlobVerdict judge(const DetectorConfig& cfg, const Blob& b, double elongation, int width,
                  int height) {
  if (b.area_px < static_cast<float>(cfg.min_area_px)) return BlobVerdict::kTooSmall;
  if (b.area_px > static_cast<float>(cfg.max_area_px)) return BlobVerdict::kTooLarge;
  if (cfg.border == BorderPolicy::kReject &&
      (b.x_min <= 0 || b.y_min <= 0 || b.x_max >= width - 1 || b.y_max >= height - 1))
    return BlobVerdict::kBorder;
  if (elongation > cfg.max_elongation) return BlobVerdict::kElongated;
  return BlobVerdict::kAccepted;
}

}  // namespace

Expected<BlobReview> review_blobs(const DetectorConfig& cfg, const ImageView& image) {
  if (image.empty()) return make_error("preview", "image", "empty image");
  if (auto r = validate_config(cfg, image.width, image.height); !r) return r.error();
  // Open limits: every component is measured; the configured ones judge it below.
  DetectorConfig open = cfg;
  open.min_area_px = 1;
  open.max_area_px = image.width * image.height;
  open.max_elongation = 1e9;
  open.border = BorderPolicy::kFlag;
  open.max_blobs = std::max(cfg.max_blobs, 4096);
  auto det = BlobDetector::create(open, image.width, image.height);
  if (!det) return det.error();
  BlobList list = det->make_blob_list();
  (void)det->detect(image, list);
  BlobReview r;
  r.config = cfg;
  r.maxval = image.maxval;
  r.threshold_dn = det->counters().last_threshold_dn;
  r.background_dn = det->counters().last_background_dn;
  r.noise_dn = det->counters().last_noise_dn;
  r.overflow = det->counters().frames_overflow > 0;
  for (int y = 0; y < image.height; ++y)
    for (int x = 0; x < image.width; ++x)
      r.image_peak_dn = std::max(r.image_peak_dn, pixel(image, x, y));
  std::vector<double> areas;
  for (const Blob& b : list) {
    ReviewedBlob rb;
    rb.blob = b;
    rb.elongation = b.minor_axis_px > 0.0f ? static_cast<double>(b.major_axis_px) /
                                                 static_cast<double>(b.minor_axis_px)
                                           : 1.0;
    rb.verdict = judge(cfg, b, rb.elongation, image.width, image.height);
    if (rb.verdict == BlobVerdict::kAccepted) {
      ++r.accepted;
      areas.push_back(static_cast<double>(b.area_px));
      r.blob_peak_dn = std::max(r.blob_peak_dn, b.peak_dn);
      if (b.has(kBlobSaturated)) ++r.saturated;
      if (b.has(kBlobMerged) || b.has(kBlobSplit)) ++r.merged;
    } else {
      ++r.rejected[static_cast<int>(rb.verdict)];
    }
    r.blobs.push_back(rb);
  }
  if (!areas.empty()) {
    std::sort(areas.begin(), areas.end());
    r.area_min_px = areas.front();
    r.area_max_px = areas.back();
    r.area_median_px = areas[areas.size() / 2];
  }
  return r;
}

std::string recommend(const BlobReview& r) {
  char line[256];
  const int small = r.rejected[static_cast<int>(BlobVerdict::kTooSmall)];
  const int large = r.rejected[static_cast<int>(BlobVerdict::kTooLarge)];
  const int border = r.rejected[static_cast<int>(BlobVerdict::kBorder)];
  const int elongated = r.rejected[static_cast<int>(BlobVerdict::kElongated)];
  const double peak_frac = static_cast<double>(r.image_peak_dn) / std::max<int>(r.maxval, 1);
  if (r.accepted == 0 && r.blobs.empty()) {
    std::snprintf(line, sizeof line,
                  "no blob above the threshold %u (image peak %u of %u): raise exposure or gain, "
                  "or lower the threshold",
                  r.threshold_dn, r.image_peak_dn, r.maxval);
  } else if (r.saturated > 0) {
    std::snprintf(line, sizeof line,
                  "peak %u of %u: %d of %d markers saturated, lower exposure or gain",
                  r.blob_peak_dn, r.maxval, r.saturated, r.accepted);
  } else if (large > 0) {
    std::snprintf(line, sizeof line,
                  "%d bright region(s) larger than max_area_px %d (reflections, lamps): cover or "
                  "mask them, or lower exposure",
                  large, r.config.max_area_px);
  } else if (small > std::max(3, r.accepted)) {
    std::snprintf(line, sizeof line,
                  "%d specks smaller than min_area_px %d (noise, stray light): raise the "
                  "threshold or lower gain",
                  small, r.config.min_area_px);
  } else if (elongated > 0) {
    std::snprintf(line, sizeof line,
                  "%d elongated blob(s) (> max_elongation %.2f): motion blur (shorten exposure) or "
                  "markers overlapping in this view",
                  elongated, r.config.max_elongation);
  } else if (border > 0) {
    std::snprintf(line, sizeof line,
                  "%d blob(s) touch the image border: aim the camera so that the working volume "
                  "lies inside the image",
                  border);
  } else if (r.accepted > 0 && peak_frac < 0.35) {
    std::snprintf(line, sizeof line,
                  "peak %u of %u: markers are dim, raise exposure or gain (aim for 50-90%% of %u)",
                  r.blob_peak_dn, r.maxval, r.maxval);
  } else {
    std::snprintf(line, sizeof line,
                  "OK: %d markers, peak %u of %u, area %.0f..%.0f px (median %.0f)", r.accepted,
                  r.blob_peak_dn, r.maxval, r.area_min_px, r.area_max_px, r.area_median_px);
  }
  return line;
}

namespace {

struct Rgb {
  std::uint8_t r, g, b;
};

Rgb colour_of(BlobVerdict v) {
  switch (v) {
    case BlobVerdict::kAccepted:
      return {0, 220, 0};
    case BlobVerdict::kTooSmall:
      return {255, 220, 0};
    case BlobVerdict::kTooLarge:
      return {255, 120, 0};
    case BlobVerdict::kBorder:
      return {0, 160, 255};
    case BlobVerdict::kElongated:
      return {255, 0, 0};
  }
  return {255, 255, 255};
}

// 3x5 glyphs of the reason letters, one row per 3 bits (MSB left).
const std::uint8_t* glyph(BlobVerdict v) {
  static const std::uint8_t kS[5] = {7, 4, 7, 1, 7}, kL[5] = {4, 4, 4, 4, 7},
                            kB[5] = {6, 5, 6, 5, 6}, kE[5] = {7, 4, 6, 4, 7};
  switch (v) {
    case BlobVerdict::kTooSmall:
      return kS;
    case BlobVerdict::kTooLarge:
      return kL;
    case BlobVerdict::kBorder:
      return kB;
    case BlobVerdict::kElongated:
      return kE;
    case BlobVerdict::kAccepted:
      break;
  }
  return nullptr;
}

void draw_box(RgbImage& out, int x0, int y0, int x1, int y1, Rgb c) {
  for (int x = x0; x <= x1; ++x) {
    out.set(x, y0, c.r, c.g, c.b);
    out.set(x, y1, c.r, c.g, c.b);
  }
  for (int y = y0; y <= y1; ++y) {
    out.set(x0, y, c.r, c.g, c.b);
    out.set(x1, y, c.r, c.g, c.b);
  }
}

}  // namespace

RgbImage draw_blob_overlay(const ImageView& image, const BlobReview& review) {
  RgbImage out(image.width, image.height);
  const double scale = 255.0 / std::max<int>(image.maxval, 1);
  for (int y = 0; y < image.height; ++y) {
    for (int x = 0; x < image.width; ++x) {
      const auto g = static_cast<std::uint8_t>(std::min(255.0, pixel(image, x, y) * scale));
      out.set(x, y, g, g, g);
    }
  }
  for (const ReviewedBlob& rb : review.blobs) {
    const Blob& b = rb.blob;
    const Rgb c = colour_of(rb.verdict);
    draw_box(out, b.x_min - 2, b.y_min - 2, b.x_max + 2, b.y_max + 2, c);
    if (rb.verdict == BlobVerdict::kAccepted) {
      const int cx = static_cast<int>(std::lround(b.x_px)),
                cy = static_cast<int>(std::lround(b.y_px));
      for (int d = -3; d <= 3; ++d) {
        out.set(cx + d, cy, 255, 0, 0);
        out.set(cx, cy + d, 255, 0, 0);
      }
    } else if (const std::uint8_t* g = glyph(rb.verdict)) {
      const int gx = b.x_max + 4, gy = b.y_min - 2;  // right of the box, 2x scale
      for (int row = 0; row < 5; ++row)
        for (int col = 0; col < 3; ++col)
          if (g[row] & (4 >> col))
            for (int k = 0; k < 4; ++k)
              out.set(gx + 2 * col + (k & 1), gy + 2 * row + (k >> 1), c.r, c.g, c.b);
    }
    if (b.has(kBlobSaturated)) {  // magenta corner: saturated
      for (int d = 0; d < 4; ++d) {
        out.set(b.x_min - 2 + d, b.y_min - 2, 255, 0, 255);
        out.set(b.x_min - 2, b.y_min - 2 + d, 255, 0, 255);
      }
    }
  }
  return out;
}

}  // namespace mocap::detect
