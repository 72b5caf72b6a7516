// Design: labelling of a wand's markers in one image. Input: the image's blob centres
// in pixel-scaled undistorted coordinates (fx x', fy y'; straight lines stay straight),
// output: which blob is wand marker 0..N-1. Every ordered pair of blobs is tried as the
// wand's two ends; each inner marker must lie within max_line_px of the end-to-end line
// at its fractional position (spacing ratio) within max_ratio_error. The wand's
// spacings are asymmetric (validate_wand), so the reversed pair fails. Exactly one
// candidate must survive: two (a stray on the line, two wands) reject the frame as
// ambiguous; a blob lying on the wand's segment that is not one of its markers also
// rejects it (a merged or split marker would corrupt the centroids). Strays elsewhere
// are tolerated. Setup-free, allocation only in the caller's output vector.
#pragma once

#include <span>
#include <vector>

#include "core/types.h"
#include "formats/wand_yaml.h"

namespace mocap::rigcal {

struct WandLabelConfig {
  double max_line_px = 2.5;       // distance of an inner marker from the end-to-end line
  double max_ratio_error = 0.08;  // error of an inner marker's fractional position
  double min_length_px = 25.0;    // shortest wand image accepted
  int max_blobs = 16;             // frames with more blobs are rejected (too many strays)
};

enum class LabelStatus { kOk, kTooFewBlobs, kTooManyBlobs, kNoWand, kAmbiguous };

const char* label_status_name(LabelStatus s) noexcept;

// order receives points' indices of wand markers 0..N-1 (when kOk).
LabelStatus label_wand(const WandSpec& wand, const WandLabelConfig& cfg,
                       std::span<const Vec2> points, std::vector<int>& order);

}  // namespace mocap::rigcal
