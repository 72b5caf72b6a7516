// Design: a per-frame background level and noise estimate from a sparse sample of
// the image (every step-th row, every step-th pixel), read into a histogram that
// was allocated at setup. Markers cover a small fraction of the image, so the median
// is the background and the distance from the lower quartile to the median gives a
// robust noise sigma (the upper half holds the markers). Each
// integer value k is treated as uniformly spread over [k - 0.5, k + 0.5) (coarser bins
// for 16-bit), so the estimates are continuous rather than stuck to integers.
// estimate() reads the sample rows itself; the detector's two-pass scan instead feeds
// the same rows through begin()/add_row()/finish() while it reads them anyway, which
// yields the identical histogram and estimate.
#pragma once

#include <cstdint>
#include <vector>

#include "core/image.h"
#include "detect/detector_config.h"

namespace mocap::detect {

struct BackgroundEstimate {
  double level_dn = 0.0;
  double noise_dn = 0.0;  // robust standard deviation
};

class BackgroundSampler {
 public:
  static constexpr int kMaxBins = 4096;  // 16-bit values are binned by a power of two

  void setup(int step_px);
  // Uses img.maxval for the histogram range (values above it count as maxval).
  BackgroundEstimate estimate(const ImageView& img, const Roi& roi) noexcept;

  // The same estimate in steps: begin() clears the histogram; add_row(img, y) must be
  // called for exactly the rows first_row(), first_row() + step(), ... inside the ROI
  // (in any order); finish() computes the estimate.
  void begin(const ImageView& img, const Roi& roi) noexcept;
  int first_row() const noexcept { return y_first_; }
  int step() const noexcept { return step_px_; }
  void add_row(const ImageView& img, int y) noexcept;
  BackgroundEstimate finish() noexcept;

 private:
  std::vector<std::uint32_t> hist_;
  int shift_ = 0;
  int bins_ = 0;
  int step_px_ = 16;
  std::uint16_t maxval_ = 255;
  int y_first_ = 0;
  int x_first_ = 0;
  int x_end_ = 0;
  std::uint64_t n_ = 0;

  double percentile(double fraction, std::uint64_t total) const noexcept;
};

}  // namespace mocap::detect
