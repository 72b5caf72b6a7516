// Design: the second half of the hot path: turn each labelled component into a Blob.
// Size and border tests come first (cheap); then the background-subtracted weighted
// centroid and the second-moment shape; elongated components are tested for two
// markers (profile along the major axis with a saddle, or strong elongation) and
// split with a two-component moment split; finally the optional 1-pixel ring below
// threshold is added to the centroid sums (it holds the partially covered edge
// pixels that thresholding cut off; docs/detection.md has the measurement). The ring
// is taken per row as the span of the 8-neighbour dilation (rows r-1..r+1, one pixel
// wider), i.e. the exact ring for row-convex blobs such as markers; for a concave
// outline it also includes the below-threshold pixels inside the row's span.
#include <algorithm>
#include <cmath>

#include "detect/blob_detector.h"

namespace mocap::detect {
namespace {

constexpr double kPixelVar = 1.0 / 12.0;  // variance of a uniform unit pixel

struct Shape {
  double l1, l2, theta;
};

Shape shape_of(double sw, double swxx, double swyy, double swxy, double cx, double cy) noexcept {
  const double a = std::max(swxx / sw - cx * cx, 0.0);
  const double d = std::max(swyy / sw - cy * cy, 0.0);
  const double b = swxy / sw - cx * cy;
  const double m = 0.5 * (a + d);
  const double r = std::sqrt(0.25 * (a - d) * (a - d) + b * b);
  return Shape{m + r, std::max(m - r, 0.0), 0.5 * std::atan2(2.0 * b, a - d)};
}

void set_shape(Blob& blob, double l1, double l2, double theta) noexcept {
  const double major = 2.0 * std::sqrt(l1 + kPixelVar);
  const double minor = 2.0 * std::sqrt(l2 + kPixelVar);
  const double q = minor / major;
  blob.major_axis_px = static_cast<float>(major);
  blob.minor_axis_px = static_cast<float>(minor);
  blob.roundness = static_cast<float>(q);
  blob.eccentricity = static_cast<float>(std::sqrt(std::max(1.0 - q * q, 0.0)));
  blob.orientation_rad = static_cast<float>(theta);
}

struct Side {
  double sw = 0, swx = 0, swy = 0;
  double area = 0;  // pixels, shared ones counted by their share
  int x_min = 1 << 30, x_max = -1, y_min = 1 << 30, y_max = -1;
  std::uint32_t peak = 0;
};

}  // namespace

template <class T>
void BlobDetector::ring_moments(const ImageView& img, const CompAcc& c, double& sw, double& swx,
                                double& swy) noexcept {
  // Row spans of the component (first bright pixel, one past the last, per row).
  const int rows = c.y_max - c.y_min + 1;
  for (int i = 0; i < rows; ++i) row_span_[i] = RowRun{1 << 30, -(1 << 30)};
  const int end = c.first + c.count;
  for (int i = c.first; i < end; ++i) {
    const RunRec& q = runs_[order_[i]];
    RowRun& sp = row_span_[q.y - c.y_min];
    sp.x_begin = std::min(sp.x_begin, q.x_begin);
    sp.x_end = std::max(sp.x_end, q.x_end);
  }
  const int xlo = roi_.x;
  const int xhi = roi_.x + roi_.width;
  const int r_first = std::max(c.y_min - 1, roi_.y);
  const int r_last = std::min(c.y_max + 1, roi_.y + roi_.height - 1);
  const int thr = threshold_;
  const int bg = background_;
  std::int64_t s0 = 0, sx = 0, sy = 0;
  for (int r = r_first; r <= r_last; ++r) {
    // Span of the 8-neighbour dilation on row r: rows r-1..r+1, widened by one pixel.
    int a = 1 << 30, b = -(1 << 30);
    for (int rr = std::max(r - 1, c.y_min); rr <= std::min(r + 1, c.y_max); ++rr) {
      a = std::min(a, row_span_[rr - c.y_min].x_begin);
      b = std::max(b, row_span_[rr - c.y_min].x_end);
    }
    a = std::max(a - 1, xlo);
    b = std::min(b + 1, xhi);
    const T* row = reinterpret_cast<const T*>(img.row8(r));
    // Pixels at or above threshold in the span are this component's own (already
    // summed); add the ones below, branch-free (the test flips at the blob's edge).
    std::int64_t rs0 = 0, rsx = 0;
    for (int x = a; x < b; ++x) {
      const int v = row[x];
      const int w = (v - bg) & -static_cast<int>(v < thr);
      rs0 += w;
      rsx += static_cast<std::int64_t>(w) * x;
    }
    s0 += rs0;
    sx += rsx;
    sy += rs0 * r;
  }
  sw += static_cast<double>(s0);
  swx += static_cast<double>(sx);
  swy += static_cast<double>(sy);
}

template <class T>
bool BlobDetector::try_split(const ImageView& img, const CompAcc& c, double cx, double cy,
                             double l1, double l2, double theta, Blob& pa, Blob& pb,
                             bool& merged) noexcept {
  merged = false;
  const double ux = std::cos(theta);
  const double uy = std::sin(theta);
  double tmin = 1e300, tmax = -1e300;
  for (int cy_i : {c.y_min, c.y_max}) {
    for (int cx_i : {c.x_min, c.x_max}) {
      const double t = (cx_i - cx) * ux + (cy_i - cy) * uy;
      tmin = std::min(tmin, t);
      tmax = std::max(tmax, t);
    }
  }
  const int nb = static_cast<int>(std::ceil(tmax - tmin)) + 2;
  if (nb < 3 || nb > static_cast<int>(profile_.size())) return false;
  std::fill(profile_.begin(), profile_.begin() + nb, 0.0);
  const int end = c.first + c.count;
  for (int i = c.first; i < end; ++i) {
    const RunRec& q = runs_[order_[i]];
    const T* row = reinterpret_cast<const T*>(img.row8(q.y));
    const double ty = (q.y - cy) * uy - tmin;
    for (int x = q.x_begin; x < q.x_end; ++x) {
      const double w = static_cast<double>(static_cast<int>(row[x]) - background_);
      const double t = (x - cx) * ux + ty;
      const int b = std::clamp(static_cast<int>(t), 0, nb - 2);
      const double f = t - b;
      profile_[b] += w * (1.0 - f);
      profile_[b + 1] += w * f;
    }
  }
  const int i0 = std::clamp(static_cast<int>(std::lround(-tmin)), 0, nb - 1);
  const auto first = profile_.begin();
  const int il = static_cast<int>(std::max_element(first, first + i0 + 1) - first);
  const int ir = static_cast<int>(std::max_element(first + i0, first + nb) - first);
  const int is = static_cast<int>(std::min_element(first + il, first + ir + 1) - first);
  const double lower_peak = std::min(profile_[il], profile_[ir]);
  const bool saddle =
      ir - il >= 2 && lower_peak > 0.0 && profile_[is] < cfg_.merge_saddle_ratio * lower_peak;
  const double elongation = std::sqrt((l1 + kPixelVar) / (l2 + kPixelVar));
  merged = saddle || elongation >= cfg_.merge_elongation_no_saddle;
  if (!merged || !cfg_.split_merged) return false;

  // Saddle position refined by a parabola through its bin and the neighbours.
  double t_cut = 0.0;
  if (saddle) {
    double off = 0.0;
    if (is > 0 && is < nb - 1) {
      const double ym = profile_[is - 1], y0 = profile_[is], yp = profile_[is + 1];
      const double den = ym - 2.0 * y0 + yp;
      if (den > 0.0) off = std::clamp(0.5 * (ym - yp) / den, -0.5, 0.5);
    }
    t_cut = is + off + tmin;
  }
  // Weights of the two sides: a pixel straddling the cut (a unit-wide cross-section
  // along the axis) is shared linearly, so the split ratio is continuous in the cut.
  Side s[2];
  for (int i = c.first; i < end; ++i) {
    const RunRec& q = runs_[order_[i]];
    const T* row = reinterpret_cast<const T*>(img.row8(q.y));
    const double ty = (q.y - cy) * uy;
    for (int x = q.x_begin; x < q.x_end; ++x) {
      const std::uint32_t v = row[x];
      const double w = static_cast<double>(static_cast<int>(v) - background_);
      const double share_a = std::clamp(t_cut - ((x - cx) * ux + ty) + 0.5, 0.0, 1.0);
      for (int k = 0; k < 2; ++k) {
        const double wk = k == 0 ? w * share_a : w * (1.0 - share_a);
        if (wk <= 0.0) continue;
        Side& sd = s[k];
        sd.sw += wk;
        sd.swx += wk * x;
        sd.swy += wk * q.y;
        sd.area += k == 0 ? share_a : 1.0 - share_a;
        sd.x_min = std::min(sd.x_min, x);
        sd.x_max = std::max(sd.x_max, x);
        sd.y_min = std::min(sd.y_min, q.y);
        sd.y_max = std::max(sd.y_max, q.y);
        sd.peak = std::max(sd.peak, v);
      }
    }
  }
  if (s[0].area <= 0.0 || s[1].area <= 0.0 || s[0].sw <= 0.0 || s[1].sw <= 0.0) return false;
  // Two-component moment split: the along-axis variance of a mixture of two equal
  // shapes exceeds the across-axis one by wa*wb/W^2 * d^2 (d = centre distance).
  const double wa = s[0].sw;
  const double wb = s[1].sw;
  const double wt = wa + wb;
  const double d = std::sqrt(std::max(l1 - l2, 0.0) * wt * wt / (wa * wb));
  const double centre[2][2] = {{cx - wb / wt * d * ux, cy - wb / wt * d * uy},
                               {cx + wa / wt * d * ux, cy + wa / wt * d * uy}};
  // A very lopsided split (one side with almost no weight) makes d explode: a centre
  // outside the component is no marker image, so keep the component whole (found by
  // fuzzing: a split centre 4 px outside a 40x41 image).
  for (const auto& ctr : centre) {
    if (!(ctr[0] >= c.x_min - 0.5 && ctr[0] <= c.x_max + 0.5 && ctr[1] >= c.y_min - 0.5 &&
          ctr[1] <= c.y_max + 0.5)) {
      return false;
    }
  }
  Blob* parts[2] = {&pa, &pb};
  for (int k = 0; k < 2; ++k) {
    Blob& p = *parts[k];
    p = Blob{};
    p.x_px = centre[k][0];
    p.y_px = centre[k][1];
    p.area_px = static_cast<float>(s[k].area);
    p.sum_dn = static_cast<float>(s[k].sw);
    p.peak_dn = static_cast<std::uint16_t>(s[k].peak);
    p.background_dn = static_cast<std::uint16_t>(background_);
    p.x_min = s[k].x_min;
    p.x_max = s[k].x_max;
    p.y_min = s[k].y_min;
    p.y_max = s[k].y_max;
    set_shape(p, l2, l2, theta);
    p.flags = kBlobMerged | kBlobSplit;
  }
  return true;
}

template <class T>
void BlobDetector::measure(const ImageView& img, BlobList& out) noexcept {
  const int rx_last = roi_.x + roi_.width - 1;
  const int ry_last = roi_.y + roi_.height - 1;
  const std::uint32_t maxval = img.maxval;
  auto touches = [&](int x0, int x1, int y0, int y1) noexcept {
    return x0 == roi_.x || x1 == rx_last || y0 == roi_.y || y1 == ry_last;
  };
  auto emit = [&](Blob& b) noexcept {
    const bool border = touches(b.x_min, b.x_max, b.y_min, b.y_max);
    if (border) {
      if (cfg_.border == BorderPolicy::kReject) {
        ++counters_.rejected_border;
        return;
      }
      b.flags |= kBlobTouchesBorder;
    }
    if (b.peak_dn >= maxval) b.flags |= kBlobSaturated;
    if (!out.push_back(b)) ++counters_.blobs_dropped;
  };
  for (int k = 0; k < n_comps_; ++k) {
    const CompAcc& c = comps_[k];
    if (c.area < cfg_.min_area_px) {
      ++counters_.rejected_small;
      continue;
    }
    if (c.area > cfg_.max_area_px) {
      ++counters_.rejected_large;
      continue;
    }
    if (cfg_.border == BorderPolicy::kReject && touches(c.x_min, c.x_max, c.y_min, c.y_max)) {
      ++counters_.rejected_border;
      continue;
    }
    const std::uint32_t truncated =
        overflow_row_ >= 0 && c.y_max >= overflow_row_ - 1 ? kBlobTruncated : 0u;
    const double cx = c.swx / c.sw;
    const double cy = c.swy / c.sw;
    const Shape sh = shape_of(c.sw, c.swxx, c.swyy, c.swxy, cx, cy);
    const double elongation = std::sqrt((sh.l1 + kPixelVar) / (sh.l2 + kPixelVar));
    Blob blob;
    blob.flags = truncated;
    if (elongation >= cfg_.merge_elongation && c.area >= 2 * cfg_.min_area_px) {
      Blob parts[2];
      bool merged = false;
      const bool split =
          try_split<T>(img, c, cx, cy, sh.l1, sh.l2, sh.theta, parts[0], parts[1], merged);
      if (merged) {
        ++counters_.merged;
        blob.flags |= kBlobMerged;
      }
      if (split) {
        ++counters_.splits;
        for (Blob& p : parts) {
          p.flags |= truncated;
          emit(p);
        }
        continue;
      }
    }
    if (elongation > cfg_.max_elongation) {
      ++counters_.rejected_elongated;
      continue;
    }
    double sw = c.sw, swx = c.swx, swy = c.swy;
    if (cfg_.centroid_ring) ring_moments<T>(img, c, sw, swx, swy);
    // Ring pixels below the background weigh negatively: on a small, faint blob in a
    // dark, noisy neighbourhood they can outweigh it and throw the centroid outside
    // the ring (found by fuzzing: x = -1.33 for a one-pixel blob at x = 0). Then the
    // ring says nothing reliable: use the component's own moments.
    const int ring_x0 = std::max(c.x_min - 1, roi_.x), ring_x1 = std::min(c.x_max + 1, rx_last);
    const int ring_y0 = std::max(c.y_min - 1, roi_.y), ring_y1 = std::min(c.y_max + 1, ry_last);
    if (!(sw > 0.0) || swx < ring_x0 * sw || swx > ring_x1 * sw || swy < ring_y0 * sw ||
        swy > ring_y1 * sw) {
      sw = c.sw;
      swx = c.swx;
      swy = c.swy;
    }
    blob.x_px = swx / sw;
    blob.y_px = swy / sw;
    blob.area_px = static_cast<float>(c.area);
    blob.sum_dn = static_cast<float>(sw);
    blob.peak_dn = static_cast<std::uint16_t>(c.peak);
    blob.background_dn = static_cast<std::uint16_t>(background_);
    blob.x_min = c.x_min;
    blob.x_max = c.x_max;
    blob.y_min = c.y_min;
    blob.y_max = c.y_max;
    set_shape(blob, sh.l1, sh.l2, sh.theta);
    emit(blob);
  }
}

template void BlobDetector::measure<std::uint8_t>(const ImageView&, BlobList&) noexcept;
template void BlobDetector::measure<std::uint16_t>(const ImageView&, BlobList&) noexcept;

}  // namespace mocap::detect
