// Design: see background.h.
#include "detect/background.h"

#include <algorithm>

namespace mocap::detect {
namespace {

// Adds row[x], row[x + step], ... (x < x_end) to four interleaved histograms:
// consecutive samples mostly hit the same background bin, and one histogram would
// serialise every increment on that bin. Returns the number of samples.
template <class T>
int bg_sample_row(const T* row, int x, int x_end, int step, int shift, int max_bin,
                  std::uint32_t* hist, int bins) noexcept {
  std::uint32_t* const h0 = hist;
  std::uint32_t* const h1 = hist + bins;
  std::uint32_t* const h2 = hist + 2 * bins;
  std::uint32_t* const h3 = hist + 3 * bins;
  auto bin = [&](int xi) noexcept { return std::min(static_cast<int>(row[xi]) >> shift, max_bin); };
  const int n = x < x_end ? (x_end - x + step - 1) / step : 0;
  int i = 0;
  for (; i + 4 <= n; i += 4, x += 4 * step) {
    const int b0 = bin(x), b1 = bin(x + step), b2 = bin(x + 2 * step), b3 = bin(x + 3 * step);
    ++h0[b0];
    ++h1[b1];
    ++h2[b2];
    ++h3[b3];
  }
  for (; i < n; ++i, x += step) ++h0[bin(x)];
  return n;
}

}  // namespace

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

void BackgroundSampler::begin(const ImageView& img, const Roi& roi) noexcept {
  maxval_ = img.maxval;
  shift_ = 0;
  while ((static_cast<int>(maxval_) >> shift_) >= kMaxBins) ++shift_;
  bins_ = (static_cast<int>(maxval_) >> shift_) + 1;
  std::fill(hist_.begin(), hist_.begin() + 4 * bins_, 0u);
  y_first_ = roi.y + std::min(step_px_ / 2, (roi.height - 1) / 2);
  x_first_ = roi.x + std::min(step_px_ / 2, (roi.width - 1) / 2);
  x_end_ = roi.x + roi.width;
  n_ = 0;
}

void BackgroundSampler::add_row(const ImageView& img, int y) noexcept {
  const int max_bin = bins_ - 1;
  const int n = img.format == PixelFormat::kMono8
                    ? bg_sample_row(img.row8(y), x_first_, x_end_, step_px_, shift_, max_bin,
                                    hist_.data(), bins_)
                    : bg_sample_row(img.row16(y), x_first_, x_end_, step_px_, shift_, max_bin,
                                    hist_.data(), bins_);
  n_ += static_cast<std::uint64_t>(n);
}

BackgroundEstimate BackgroundSampler::finish() noexcept {
  if (n_ == 0) return {};
  // Fold the four interleaved histograms into the first.
  std::uint32_t* const hist = hist_.data();
  const int bins = bins_;
  for (int b = 0; b < bins; ++b) {
    hist[b] += hist[bins + b] + hist[2 * bins + b] + hist[3 * bins + b];
  }
  BackgroundEstimate e;
  e.level_dn = std::max(percentile(0.5, n_), 0.0);
  // Lower half only: bright markers sit in the upper tail and must not inflate sigma.
  e.noise_dn = std::max((e.level_dn - percentile(0.25, n_)) / 0.6745, 0.0);
  return e;
}

BackgroundEstimate BackgroundSampler::estimate(const ImageView& img, const Roi& roi) noexcept {
  begin(img, roi);
  for (int y = y_first_; y < roi.y + roi.height; y += step_px_) add_row(img, y);
  return finish();
}

}  // namespace mocap::detect
