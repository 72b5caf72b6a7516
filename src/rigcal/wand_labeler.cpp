// Design: see wand_labeler.h. O(n^2 * N * n) for n blobs and N markers (n <= 16).
#include "rigcal/wand_labeler.h"

#include <cmath>

namespace mocap::rigcal {

const char* label_status_name(LabelStatus s) noexcept {
  switch (s) {
    case LabelStatus::kOk:
      return "ok";
    case LabelStatus::kTooFewBlobs:
      return "too few blobs";
    case LabelStatus::kTooManyBlobs:
      return "too many blobs";
    case LabelStatus::kNoWand:
      return "no wand";
    case LabelStatus::kAmbiguous:
      return "ambiguous";
  }
  return "?";
}

LabelStatus label_wand(const WandSpec& wand, const WandLabelConfig& cfg,
                       std::span<const Vec2> points, std::vector<int>& order) {
  const auto N = wand.markers_mm.size();
  const auto n = points.size();
  if (N < 2 || n < N) return LabelStatus::kTooFewBlobs;
  if (n > static_cast<std::size_t>(cfg.max_blobs)) return LabelStatus::kTooManyBlobs;
  const double len_mm = wand.length_mm();
  int found = 0;
  std::vector<int> cand(N, -1);
  for (std::size_t i = 0; i < n; ++i) {
    for (std::size_t j = 0; j < n; ++j) {
      if (i == j) continue;
      const Vec2 axis = points[j] - points[i];
      const double L = axis.norm();
      if (L < cfg.min_length_px) continue;
      const Vec2 u = axis / L;
      cand[0] = static_cast<int>(i);
      cand[N - 1] = static_cast<int>(j);
      bool ok = true;
      for (std::size_t k = 1; k + 1 < N && ok; ++k) {
        const double r = (wand.markers_mm[k] - wand.markers_mm[0]) / len_mm;
        int best = -1;
        double best_err = cfg.max_ratio_error;
        for (std::size_t b = 0; b < n; ++b) {
          if (b == i || b == j) continue;
          const Vec2 d = points[b] - points[i];
          const double along = d.dot(u) / L;
          const double perp = std::fabs(d.x() * u.y() - d.y() * u.x());
          const double err = std::fabs(along - r);
          if (perp <= cfg.max_line_px && err < best_err) {
            best_err = err;
            best = static_cast<int>(b);
          }
        }
        if (best < 0) ok = false;
        cand[k] = best;
      }
      if (!ok) continue;
      // Any other blob on the segment (extended by 5% each side) makes the frame unsafe.
      for (std::size_t b = 0; b < n && ok; ++b) {
        bool member = false;
        for (int c : cand) member = member || c == static_cast<int>(b);
        if (member) continue;
        const Vec2 d = points[b] - points[i];
        const double along = d.dot(u) / L;
        const double perp = std::fabs(d.x() * u.y() - d.y() * u.x());
        if (perp <= 2.0 * cfg.max_line_px && along > -0.05 && along < 1.05) ok = false;
      }
      if (!ok) return LabelStatus::kAmbiguous;
      ++found;
      if (found > 1) return LabelStatus::kAmbiguous;
      order = cand;
    }
  }
  return found == 1 ? LabelStatus::kOk : LabelStatus::kNoWand;
}

}  // namespace mocap::rigcal
