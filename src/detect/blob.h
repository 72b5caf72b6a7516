// Design: the detector's output types. A Blob is one marker image: sub-pixel
// centroid (pixel centre of the top-left pixel = (0,0), as in camera/camera_model.h),
// size, bounding box, peak and second-moment shape, plus flags. BlobList is the
// core BoundedList of blobs (storage allocated once at setup; the hot path only
// overwrites it and counts what did not fit) plus the frame's image levels. DetectorCounters
// accumulate over the detector's lifetime (failures become counters, never exceptions or logs).
#pragma once

#include <cstddef>
#include <cstdint>

#include "core/bounded_list.h"

namespace mocap::detect {

// Bit flags of Blob::flags.
enum BlobFlag : std::uint32_t {
  kBlobTouchesBorder = 1u << 0,  // has a pixel on the image (or ROI) border: may be cut off
  kBlobSaturated = 1u << 1,      // peak reached the image's maxval
  kBlobMerged = 1u << 2,         // looks like two overlapping markers (elongated, two maxima)
  kBlobSplit = 1u << 3,          // one of two blobs produced by splitting a merged blob
  kBlobTruncated = 1u << 4,      // the run buffer overflowed while this blob was open
};

struct Blob {
  double x_px = 0.0;     // sub-pixel centroid (column), background-subtracted intensity-weighted
  double y_px = 0.0;     // sub-pixel centroid (row)
  float area_px = 0.0f;  // pixels at or above threshold (after a split: this part's share)
  float sum_dn = 0.0f;   // sum of (pixel - background) over the centroid's pixels
  std::uint16_t peak_dn = 0;                       // brightest pixel value (raw DN)
  std::uint16_t background_dn = 0;                 // background level used for the weights
  int x_min = 0, y_min = 0, x_max = 0, y_max = 0;  // inclusive bounding box (pixels)
  float major_axis_px = 0.0f;    // 2*sqrt(largest eigenvalue of the weighted covariance)
  float minor_axis_px = 0.0f;    // 2*sqrt(smallest eigenvalue)
  float roundness = 0.0f;        // minor/major in (0, 1]; 1 = circle
  float eccentricity = 0.0f;     // sqrt(1 - (minor/major)^2); 0 = circle
  float orientation_rad = 0.0f;  // major-axis angle from +x towards +y, in (-pi/2, pi/2]
  std::uint32_t flags = 0;       // BlobFlag bits

  bool has(BlobFlag f) const noexcept { return (flags & f) != 0; }
};

// The blobs of one frame: a BoundedList (capacity chosen at setup, never grows in the
// hot path) that also carries the image levels the detector used for the frame.
class BlobList : public BoundedList<Blob> {
 public:
  using BoundedList<Blob>::BoundedList;

  // The image levels the detector used for this list's frame (background and noise
  // sigma estimate, threshold; DN). Consumers judging blob shapes (track/marker_shape.h)
  // read them here, on the thread that owns the list, not from the detector's counters.
  struct Levels {
    double background_dn = 0.0;
    double noise_dn = 0.0;
    double threshold_dn = 0.0;
  };
  void set_levels(const Levels& levels) noexcept { levels_ = levels; }
  const Levels& levels() const noexcept { return levels_; }

 private:
  Levels levels_{};
};

// Lifetime counters (monotonic). The last frame's values are in last_* fields.
struct DetectorCounters {
  std::uint64_t frames = 0;
  std::uint64_t frames_invalid = 0;      // wrong size/format/null data: nothing detected
  std::uint64_t frames_no_contrast = 0;  // threshold above maxval (e.g. all white): no blobs
  std::uint64_t frames_overflow = 0;     // frames with run or blob overflow
  std::uint64_t runs_overflow = 0;       // frames whose run buffer filled (scan stopped early)
  std::uint64_t blobs_dropped = 0;       // accepted blobs that did not fit the BlobList
  std::uint64_t components = 0;          // connected components found
  std::uint64_t rejected_small = 0;
  std::uint64_t rejected_large = 0;
  std::uint64_t rejected_elongated = 0;
  std::uint64_t rejected_border = 0;
  std::uint64_t merged = 0;  // components flagged as merged
  std::uint64_t splits = 0;  // merged components split into two blobs
  // Last frame.
  std::uint32_t last_runs = 0;
  std::uint32_t last_components = 0;
  std::uint32_t last_blobs = 0;
  double last_background_dn = 0.0;
  double last_noise_dn = 0.0;
  std::uint32_t last_threshold_dn = 0;
};

}  // namespace mocap::detect
