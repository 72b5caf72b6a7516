// Design: every knob of the blob detector in one plain struct, validated once at
// setup (validate_config returns a one-line error "detector: key: problem"). Values
// in DN are in the image's own units (8-bit: 0..255; 16-bit: 0..maxval); the
// detector scales nothing silently.
#pragma once

#include <cstdint>
#include <string>

#include "core/expected.h"

namespace mocap::detect {

enum class ThresholdMode : std::uint8_t {
  kFixed,     // threshold = threshold_dn; background = background_dn
  kAdaptive,  // per frame: background and noise from a sparse sample histogram;
              // threshold = background + max(threshold_sigma * noise, min_contrast_dn)
};

enum class BorderPolicy : std::uint8_t {
  kFlag,    // keep blobs touching the border, flag kBlobTouchesBorder
  kReject,  // drop them (counted)
};

enum class SimdLevel : std::uint8_t { kAuto, kScalar, kSse2, kAvx2 };

// Region of interest in pixels; width or height 0 = the whole image.
struct Roi {
  int x = 0, y = 0, width = 0, height = 0;
};

struct DetectorConfig {
  ThresholdMode threshold_mode = ThresholdMode::kAdaptive;
  int threshold_dn = 40;               // kFixed: absolute threshold (pixel >= threshold is bright)
  int background_dn = 0;               // kFixed: background subtracted in the centroid weights
  double threshold_sigma = 6.0;        // kAdaptive: threshold above background in noise sigmas
  int min_contrast_dn = 12;            // kAdaptive: minimum threshold above background
  int background_sample_step_px = 16;  // kAdaptive: sample every N-th row and column

  int min_area_px = 4;          // smaller components are rejected (noise)
  int max_area_px = 20000;      // larger components are rejected (reflections, glare)
  double max_elongation = 4.0;  // major/minor axis ratio above this is rejected (after split)
  BorderPolicy border = BorderPolicy::kFlag;
  Roi roi{};

  // Sub-pixel estimator: include the 1-pixel ring just below threshold around each blob
  // in the background-subtracted centroid (captures the partially covered edge pixels).
  bool centroid_ring = true;

  // Merged-blob handling: a component whose elongation exceeds merge_elongation and
  // whose profile along the major axis has two maxima with a saddle below
  // merge_saddle_ratio * (smaller maximum), or whose elongation exceeds
  // merge_elongation_no_saddle, is flagged kBlobMerged and, if split_merged,
  // replaced by two blobs.
  bool split_merged = true;
  double merge_elongation = 1.3;
  double merge_saddle_ratio = 0.92;
  // Above this elongation a component is taken as merged even without a saddle
  // (heavily overlapping markers have a single-peaked profile).
  double merge_elongation_no_saddle = 1.6;

  int max_blobs = 512;   // BlobList capacity; more accepted blobs are dropped (counted)
  int max_runs = 32768;  // bright runs per frame; more stop the scan (counted)
  SimdLevel simd = SimdLevel::kAuto;
  // Scan strategy; both give bit-identical blobs. false (default): two passes, one
  // read of every row that records per-chunk maxima (and feeds the background
  // histogram its sample rows), then run extraction in the chunks that reach the
  // threshold only. true: the reference scan, a separate sparse read for the
  // background estimate and then every row through the run kernel.
  bool full_scan = false;
};

// One-line error naming the key, or success. width/height: the image size.
Expected<void> validate_config(const DetectorConfig& cfg, int width, int height);

}  // namespace mocap::detect
