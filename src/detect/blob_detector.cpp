// Design: setup (validation, workspace allocation) and the first half of the hot
// path: threshold choice, the run scan (two-pass: chunk maxima, then runs in the
// bright chunks; or the full reference scan) with per-run moments and incremental
// union-find labelling, and component resolution. Measuring the components is in
// blob_measure.cpp. See blob_detector.h for the algorithm.
#include "detect/blob_detector.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

namespace mocap::detect {
namespace {

Error bad(const std::string& key, const std::string& what) {
  return make_error("detector", key, what);
}

std::string num(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g", v);
  return buf;
}

int find_root(std::vector<BlobDetector::RunRec>& runs, int i) noexcept {
  while (runs[i].parent != i) {
    runs[i].parent = runs[runs[i].parent].parent;  // path halving
    i = runs[i].parent;
  }
  return i;
}

}  // namespace

Expected<void> validate_config(const DetectorConfig& c, int width, int height) {
  if (width < 1 || width > 32768)
    return bad("width", "must be in [1, 32768] (got " + num(width) + ")");
  if (height < 1 || height > 32768)
    return bad("height", "must be in [1, 32768] (got " + num(height) + ")");
  if (c.threshold_mode == ThresholdMode::kFixed) {
    if (c.threshold_dn < 1 || c.threshold_dn > 65535)
      return bad("threshold_dn", "must be in [1, 65535] (got " + num(c.threshold_dn) + ")");
    if (c.background_dn < 0 || c.background_dn >= c.threshold_dn)
      return bad("background_dn",
                 "must be in [0, threshold_dn) (got " + num(c.background_dn) + ")");
  }
  if (!std::isfinite(c.threshold_sigma) || c.threshold_sigma < 0.0)
    return bad("threshold_sigma", "must be finite and >= 0 (got " + num(c.threshold_sigma) + ")");
  if (c.min_contrast_dn < 1 || c.min_contrast_dn > 65535)
    return bad("min_contrast_dn", "must be in [1, 65535] (got " + num(c.min_contrast_dn) + ")");
  if (c.background_sample_step_px < 1 || c.background_sample_step_px > 4096)
    return bad("background_sample_step_px",
               "must be in [1, 4096] (got " + num(c.background_sample_step_px) + ")");
  if (c.min_area_px < 1) return bad("min_area_px", "must be >= 1 (got " + num(c.min_area_px) + ")");
  if (c.max_area_px < c.min_area_px)
    return bad("max_area_px", "must be >= min_area_px (got " + num(c.max_area_px) + ")");
  if (!(c.max_elongation >= 1.0))
    return bad("max_elongation", "must be >= 1 (got " + num(c.max_elongation) + ")");
  if (!(c.merge_elongation >= 1.0))
    return bad("merge_elongation", "must be >= 1 (got " + num(c.merge_elongation) + ")");
  if (!(c.merge_elongation_no_saddle >= c.merge_elongation))
    return bad("merge_elongation_no_saddle",
               "must be >= merge_elongation (got " + num(c.merge_elongation_no_saddle) + ")");
  if (!(c.merge_saddle_ratio > 0.0 && c.merge_saddle_ratio <= 1.0))
    return bad("merge_saddle_ratio", "must be in (0, 1] (got " + num(c.merge_saddle_ratio) + ")");
  const Roi& r = c.roi;
  if (r.x < 0 || r.y < 0 || r.width < 0 || r.height < 0) return bad("roi", "negative value");
  if ((r.width > 0) != (r.height > 0))
    return bad("roi", "width and height must both be 0 or both > 0");
  if (r.width > 0 && (r.x + r.width > width || r.y + r.height > height))
    return bad("roi", "outside the " + num(width) + "x" + num(height) + " image");
  if (c.max_blobs < 1 || c.max_blobs > (1 << 20))
    return bad("max_blobs", "must be in [1, 1048576] (got " + num(c.max_blobs) + ")");
  if (c.max_runs < 1 || c.max_runs > (1 << 24))
    return bad("max_runs", "must be in [1, 16777216] (got " + num(c.max_runs) + ")");
  return {};
}

Expected<BlobDetector> BlobDetector::create(const DetectorConfig& cfg, int width, int height) {
  if (auto v = validate_config(cfg, width, height); !v) return v.error();
  BlobDetector d;
  d.cfg_ = cfg;
  d.width_ = width;
  d.height_ = height;
  d.roi_ = cfg.roi.width > 0 ? cfg.roi : Roi{0, 0, width, height};
  d.kernels_ = select_row_run_kernels(cfg.simd);
  d.chunk_kernels_ = select_chunk_max_kernels(d.kernels_.level);
  d.chunks_per_row_ = chunk_count(0, d.roi_.width, std::min(kChunkPx8, kChunkPx16));
  d.sampler_.setup(cfg.background_sample_step_px);
  const auto max_runs = static_cast<std::size_t>(cfg.max_runs);
  d.row_runs_.resize(static_cast<std::size_t>(d.roi_.width / 2 + 1));
  d.runs_.resize(max_runs);
  d.comps_.resize(max_runs);
  d.order_.resize(max_runs);
  d.row_span_.resize(static_cast<std::size_t>(d.roi_.height));
  d.profile_.resize(static_cast<std::size_t>(2 * (d.roi_.width + d.roi_.height) + 8));
  if (!cfg.full_scan) {
    d.chunk_max_.resize(static_cast<std::size_t>(d.chunks_per_row_) *
                        static_cast<std::size_t>(d.roi_.height));
    d.row_max_.resize(static_cast<std::size_t>(d.roi_.height));
  }
  return d;
}

template <class T>
void BlobDetector::summarise(const ImageView& img, bool sample_background) noexcept {
  if (sample_background) sampler_.begin(img, roi_);
  int next_sample = sample_background ? sampler_.first_row() : -1;
  const int x0 = roi_.x;
  const int x1 = roi_.x + roi_.width;
  for (int i = 0; i < roi_.height; ++i) {
    const int y = roi_.y + i;
    const T* row = reinterpret_cast<const T*>(img.row8(y));
    std::uint16_t* cm = chunk_max_.data() + static_cast<std::ptrdiff_t>(i) * chunks_per_row_;
    if constexpr (sizeof(T) == 1) {
      row_max_[i] = chunk_kernels_.k8(row, x0, x1, cm);
    } else {
      row_max_[i] = chunk_kernels_.k16(row, x0, x1, cm);
    }
    if (y == next_sample) {  // the row is in L1 now
      sampler_.add_row(img, y);
      next_sample += sampler_.step();
    }
  }
}

template <class T>
int BlobDetector::row_kernel(const T* row, int x0, int x1, RowRun* out, int cap) const noexcept {
  const auto thr = static_cast<std::uint16_t>(threshold_);
  if constexpr (sizeof(T) == 1) {
    return kernels_.k8(row, x0, x1, thr, out, cap);
  } else {
    return kernels_.k16(row, x0, x1, thr, out, cap);
  }
}

// The runs of ROI row y from its bright chunks only: each maximal stretch of chunks
// whose maximum reaches the threshold goes through the run kernel. The pixels on
// either side of a stretch are dark (or outside the ROI), so these are exactly the
// row's runs, in order; the return value follows the kernel's overflow convention.
template <class T>
int BlobDetector::bright_chunk_runs(const T* row, int y, int room) noexcept {
  constexpr int kChunk = sizeof(T) == 1 ? kChunkPx8 : kChunkPx16;
  const int i = y - roi_.y;
  const auto thr = static_cast<std::uint16_t>(threshold_);
  if (row_max_[i] < thr) return 0;
  const std::uint16_t* cm = chunk_max_.data() + static_cast<std::ptrdiff_t>(i) * chunks_per_row_;
  const int x0 = roi_.x;
  const int x1 = roi_.x + roi_.width;
  const int nc = chunk_count(x0, x1, kChunk);
  int n = 0;
  for (int c = 0; c < nc;) {
    if (cm[c] < thr) {
      ++c;
      continue;
    }
    int e = c + 1;
    while (e < nc && cm[e] >= thr) ++e;
    const int a = x0 + c * kChunk;
    const int b = std::min(x0 + e * kChunk, x1);
    const int got = row_kernel(row, a, b, row_runs_.data() + n, room - n);
    if (got > room - n) return room + 1;
    n += got;
    c = e;
  }
  return n;
}

template <class T>
void BlobDetector::scan(const ImageView& img) noexcept {
  n_runs_ = 0;
  overflow_row_ = -1;
  const bool two_pass = !cfg_.full_scan;
  const int x0 = roi_.x;
  const int x1 = roi_.x + roi_.width;
  const int row_cap = static_cast<int>(row_runs_.size());
  int prev_begin = 0;
  int prev_end = 0;
  for (int y = roi_.y; y < roi_.y + roi_.height; ++y) {
    const T* row = reinterpret_cast<const T*>(img.row8(y));
    const int room = std::min(cfg_.max_runs - n_runs_, row_cap);
    int n = two_pass ? bright_chunk_runs(row, y, room)
                     : row_kernel(row, x0, x1, row_runs_.data(), room);
    if (n > room) {
      overflow_row_ = y;
      n = room;
    }
    const int cur_begin = n_runs_;
    int p = prev_begin;
    for (int k = 0; k < n; ++k) {
      const RowRun rr = row_runs_[k];
      RunRec& r = runs_[n_runs_];
      std::int64_t sw = 0, swx = 0, swxx = 0;
      std::uint32_t peak = 0;
      for (int x = rr.x_begin; x < rr.x_end; ++x) {
        const std::uint32_t v = row[x];
        const std::int64_t w = static_cast<std::int64_t>(v) - background_;
        sw += w;
        swx += w * x;
        swxx += w * x * x;
        peak = std::max(peak, v);
      }
      r = RunRec{y, rr.x_begin, rr.x_end, n_runs_, sw, swx, swxx, peak, -1};
      // 8-connectivity with the previous row: overlap of [b-1, e] with [pb, pe).
      while (p < prev_end && runs_[p].x_end < rr.x_begin) ++p;
      for (int q = p; q < prev_end && runs_[q].x_begin <= rr.x_end; ++q) {
        const int ra = find_root(runs_, n_runs_);
        const int rb = find_root(runs_, q);
        if (ra != rb) runs_[std::max(ra, rb)].parent = std::min(ra, rb);
      }
      ++n_runs_;
    }
    prev_begin = cur_begin;
    prev_end = n_runs_;
    if (overflow_row_ >= 0) break;
  }
}

void BlobDetector::resolve_components() noexcept {
  // Roots have the smallest index of their set and every parent index is smaller than
  // its child's, so one forward pass labels each run with its root's component.
  n_comps_ = 0;
  for (int i = 0; i < n_runs_; ++i) {
    RunRec& r = runs_[i];
    if (r.parent == i) {
      r.comp = n_comps_;
      comps_[n_comps_] = CompAcc{0, 0, 0, 0, 0, 0, 0, r.x_begin, r.x_end - 1, r.y, r.y, 0, 0, 0};
      ++n_comps_;
    } else {
      r.comp = runs_[r.parent].comp;
    }
  }
  for (int i = 0; i < n_runs_; ++i) {
    const RunRec& r = runs_[i];
    CompAcc& c = comps_[r.comp];
    const auto sw = static_cast<double>(r.sw);
    const auto swx = static_cast<double>(r.swx);
    const auto y = static_cast<double>(r.y);
    c.sw += sw;
    c.swx += swx;
    c.swy += sw * y;
    c.swxx += static_cast<double>(r.swxx);
    c.swyy += sw * y * y;
    c.swxy += swx * y;
    c.area += r.x_end - r.x_begin;
    c.x_min = std::min(c.x_min, r.x_begin);
    c.x_max = std::max(c.x_max, r.x_end - 1);
    c.y_max = std::max(c.y_max, r.y);
    c.peak = std::max(c.peak, r.peak);
    ++c.count;
  }
  // Group runs by component (counting sort keeps row order within a component).
  int acc = 0;
  for (int k = 0; k < n_comps_; ++k) {
    comps_[k].first = acc;
    acc += comps_[k].count;
    comps_[k].count = 0;
  }
  for (int i = 0; i < n_runs_; ++i) {
    CompAcc& c = comps_[runs_[i].comp];
    order_[c.first + c.count++] = i;
  }
}

bool BlobDetector::detect(const ImageView& img, BlobList& out) noexcept {
  out.clear();
  ++counters_.frames;
  const bool fmt_ok = img.format == PixelFormat::kMono8 || img.format == PixelFormat::kMono16;
  if (img.empty() || !fmt_ok || img.width != width_ || img.height != height_ ||
      img.stride_bytes < img.width * bytes_per_pixel(img.format) || img.maxval == 0 ||
      (img.format == PixelFormat::kMono8 && img.maxval > 255)) {
    ++counters_.frames_invalid;
    counters_.last_runs = counters_.last_components = counters_.last_blobs = 0;
    return false;
  }
  const int maxval = img.maxval;
  double noise = 0.0;
  double level = cfg_.background_dn;
  int thr = cfg_.threshold_dn;
  const bool adaptive = cfg_.threshold_mode == ThresholdMode::kAdaptive;
  if (!cfg_.full_scan) {
    if (img.format == PixelFormat::kMono8) {
      summarise<std::uint8_t>(img, adaptive);
    } else {
      summarise<std::uint16_t>(img, adaptive);
    }
  }
  if (adaptive) {
    const BackgroundEstimate e = cfg_.full_scan ? sampler_.estimate(img, roi_) : sampler_.finish();
    level = e.level_dn;
    noise = e.noise_dn;
    const double above = std::max(cfg_.threshold_sigma * noise, double{1.0} * cfg_.min_contrast_dn);
    thr = static_cast<int>(std::ceil(level + above));
  }
  if (thr > maxval) {
    // The background is so bright that no pixel can stand out: nothing to detect.
    ++counters_.frames_no_contrast;
    counters_.last_background_dn = level;
    counters_.last_noise_dn = noise;
    counters_.last_threshold_dn = static_cast<std::uint32_t>(thr);
    counters_.last_runs = counters_.last_components = counters_.last_blobs = 0;
    return true;
  }
  threshold_ = std::max(thr, 1);
  background_ = std::clamp(static_cast<int>(std::lround(level)), 0, threshold_ - 1);
  counters_.last_background_dn = level;
  counters_.last_noise_dn = noise;
  counters_.last_threshold_dn = static_cast<std::uint32_t>(threshold_);
  out.set_levels(BlobList::Levels{level, noise, static_cast<double>(threshold_)});

  if (img.format == PixelFormat::kMono8) {
    scan<std::uint8_t>(img);
  } else {
    scan<std::uint16_t>(img);
  }
  resolve_components();
  const std::uint64_t dropped_before = counters_.blobs_dropped;
  if (img.format == PixelFormat::kMono8) {
    measure<std::uint8_t>(img, out);
  } else {
    measure<std::uint16_t>(img, out);
  }
  counters_.last_runs = static_cast<std::uint32_t>(n_runs_);
  counters_.last_components = static_cast<std::uint32_t>(n_comps_);
  counters_.last_blobs = static_cast<std::uint32_t>(out.size());
  counters_.components += static_cast<std::uint64_t>(n_comps_);
  const bool overflow = overflow_row_ >= 0 || counters_.blobs_dropped != dropped_before;
  if (overflow_row_ >= 0) ++counters_.runs_overflow;
  if (overflow) ++counters_.frames_overflow;
  return !overflow;
}

}  // namespace mocap::detect
