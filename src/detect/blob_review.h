// Design: what an operator needs to aim a camera and set its exposure and threshold
// (`mocap preview`; later the live 3D view): every bright component of one image, each
// with the verdict the detector's configured thresholds give it, plus the image's peak
// brightness and a one-line recommendation.
//   review_blobs runs the detector (src/detect, the same code as tracking) once with the
//   size, elongation and border limits opened up, so that rejected components are
//   measured too, and judges each one against the CONFIGURED limits in the detector's own
//   order: too small, too large, touching the border (when the policy rejects them),
//   elongated. Saturated and merged blobs are flagged (accepted, but their centroids are
//   biased). Thresholds and background are the detector's own for this frame.
//   draw_blob_overlay renders the image in grey with each blob marked: accepted ones with
//   a green box and a red centroid cross, rejected ones with a box in the colour of their
//   reason and its letter (S small, L large, B border, E elongated); saturated blobs get a
//   magenta corner mark.
// Setup / diagnostic code: allocates, not for the hot path.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "core/expected.h"
#include "core/image.h"
#include "core/rgb_image.h"
#include "detect/blob.h"
#include "detect/detector_config.h"

namespace mocap::detect {

enum class BlobVerdict : std::uint8_t { kAccepted, kTooSmall, kTooLarge, kBorder, kElongated };

const char* to_string(BlobVerdict v) noexcept;  // "accepted", "too small", ...

struct ReviewedBlob {
  Blob blob;
  BlobVerdict verdict = BlobVerdict::kAccepted;
  double elongation = 1.0;  // major / minor axis
};

struct BlobReview {
  std::vector<ReviewedBlob> blobs;
  int accepted = 0;
  int rejected[5] = {0, 0, 0, 0, 0};  // by BlobVerdict (index 0 unused)
  int saturated = 0;                  // accepted blobs whose peak reached maxval
  int merged = 0;                     // accepted blobs flagged merged/split
  std::uint16_t image_peak_dn = 0;    // brightest pixel of the image
  std::uint16_t maxval = 255;
  std::uint16_t blob_peak_dn = 0;                               // brightest accepted blob
  double area_min_px = 0, area_median_px = 0, area_max_px = 0;  // accepted blobs
  std::uint32_t threshold_dn = 0;  // the detector's threshold for this frame
  double background_dn = 0.0, noise_dn = 0.0;
  bool overflow = false;  // more components than the review could hold
  DetectorConfig config;  // the configured limits judged against
};

// Reviews one image against `cfg` (validated here; errors name the detector key).
Expected<BlobReview> review_blobs(const DetectorConfig& cfg, const ImageView& image);

// One line: the most important thing to change, or "OK: ...".
std::string recommend(const BlobReview& review);

// The overlay picture of `image` (same size) with the reviewed blobs drawn.
RgbImage draw_blob_overlay(const ImageView& image, const BlobReview& review);

}  // namespace mocap::detect
