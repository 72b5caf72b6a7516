// Design: see background.h.
#include "detect/background.h"

#include <algorithm>

namespace mocap::detect {

void BackgroundSampler::setup(int step_px) {
  step_px_ = std::max(step_px, 1);
  hist_.assign(4 * kMaxBins, 0u);
}

double BackgroundSampler::percentile(double fraction, std::uint64_t total) const noexcept {
  const double target = fraction * static_cast<double>(total);
  double below = 0.0;
  const double bin_dn = static_cast<double>(1 << shift_);
  for (int b = 0; b < bins_; ++b) {
    const double c = static_cast<double>(hist_[b]);
    if (c > 0.0 && below + c >= target) {
      const double lo = static_cast<double>(b) * bin_dn - 0.5;
      return lo + bin_dn * (target - below) / c;
    }
    below += c;
  }
  return static_cast<double>(maxval_);
}

// Four interleaved histograms: consecutive samples mostly hit the same background
// bin, and one histogram would serialise every increment on that bin.
template <class T>
static std::uint64_t sample(const ImageView& img, const Roi& roi, int step_y, int step_x, int shift,
                            std::uint32_t* hist, int bins) noexcept {
  std::uint64_t n = 0;
  const int max_bin = bins - 1;
  const int y_first = roi.y + std::min(step_y / 2, (roi.height - 1) / 2);
  const int x_first = roi.x + std::min(step_x / 2, (roi.width - 1) / 2);
  for (int y = y_first; y < roi.y + roi.height; y += step_y) {
    const T* row = reinterpret_cast<const T*>(img.row8(y));
    int k = 0;
    for (int x = x_first; x < roi.x + roi.width; x += step_x) {
      const int b = std::min(static_cast<int>(row[x]) >> shift, max_bin);
      ++hist[k * bins + b];
      k = (k + 1) & 3;
      ++n;
    }
  }
  for (int b = 0; b < bins; ++b)
    hist[b] += hist[bins + b] + hist[2 * bins + b] + hist[3 * bins + b];
  return n;
}

BackgroundEstimate BackgroundSampler::estimate(const ImageView& img, const Roi& roi) noexcept {
  maxval_ = img.maxval;
  shift_ = 0;
  while ((static_cast<int>(maxval_) >> shift_) >= kMaxBins) ++shift_;
  bins_ = (static_cast<int>(maxval_) >> shift_) + 1;
  std::fill(hist_.begin(), hist_.begin() + 4 * bins_, 0u);
  const int step_x = step_px_;
  const std::uint64_t n =
      img.format == PixelFormat::kMono8
          ? sample<std::uint8_t>(img, roi, step_px_, step_x, shift_, hist_.data(), bins_)
          : sample<std::uint16_t>(img, roi, step_px_, step_x, shift_, hist_.data(), bins_);
  if (n == 0) return {};
  BackgroundEstimate e;
  e.level_dn = std::max(percentile(0.5, n), 0.0);
  // Lower half only: bright markers sit in the upper tail and must not inflate sigma.
  e.noise_dn = std::max((e.level_dn - percentile(0.25, n)) / 0.6745, 0.0);
  return e;
}

}  // namespace mocap::detect
