// Design: see exhaustive_search.h. Depth-first over the model markers in index order:
// marker a takes any available point consistent (pair discrepancy < t) with the markers
// already taken, or none. Only feasibility prunes; the score is evaluated at every
// assignment with m >= min_markers (the Umeyama residual test is applied there).
#include "identify/exhaustive_search.h"

#include <cmath>

namespace mocap {
namespace {

struct Exhaustive {
  const TargetModel& model;
  FramePoints& frame;
  const IdentifyConfig& config;
  SearchResult& best;
  std::array<std::int16_t, kMaxMarkers> assign{};
  FitPoints src{3, kMaxMarkers};
  FitPoints dst{3, kMaxMarkers};

  void evaluate(int m) {
    int c = 0;
    for (int a = 0; a < model.k; ++a) {
      const int p = assign[static_cast<std::size_t>(a)];
      if (p < 0) continue;
      src.col(c) = model.M_body[static_cast<std::size_t>(a)];
      dst.col(c) = frame.X(p);
      ++c;
    }
    const RigidFit fit = fit_rigid(src, dst, m);
    if (!(fit.max_sq_mm2 < config.t_mm * config.t_mm)) return;
    const double floor2 = config.residual_floor_mm * config.residual_floor_mm;
    const double score =
        std::sqrt(fit.sum_sq_mm2 + m * floor2) * model.score_factor[static_cast<std::size_t>(m)];
    if (best.found && !(score < best.score || (score == best.score && m > best.m))) return;
    best.found = true;
    best.m = m;
    best.score = score;
    best.sum_sq_mm2 = fit.sum_sq_mm2;
    best.rms_mm = std::sqrt(fit.sum_sq_mm2 / m);
    best.T_world_body = fit.T_dst_src;
    best.point_of_marker = assign;
  }

  void recurse(int a, int m) {
    if (a == model.k) {
      if (m >= config.min_markers) evaluate(m);
      return;
    }
    const auto as = static_cast<std::size_t>(a);
    for (int p = 0; p < frame.size(); ++p) {
      if (!frame.available(p)) continue;
      bool ok = true;
      for (int b = 0; b < a && ok; ++b) {
        const int q = assign[static_cast<std::size_t>(b)];
        if (q < 0) continue;
        const double d = (frame.X(p) - frame.X(q)).norm();
        ok = std::abs(d - model.dist_mm[as][static_cast<std::size_t>(b)]) < config.t_mm;
      }
      if (!ok) continue;
      assign[as] = static_cast<std::int16_t>(p);
      frame.acquire(p);
      recurse(a + 1, m + 1);
      frame.release(p);
    }
    assign[as] = -1;
    recurse(a + 1, m);
  }
};

}  // namespace

bool exhaustive_search(const TargetModel& model, FramePoints& frame, const IdentifyConfig& config,
                       SearchResult& out) noexcept {
  out = SearchResult{};
  out.point_of_marker.fill(-1);
  Exhaustive ex{model, frame, config, out};
  ex.assign.fill(-1);
  ex.recurse(0, 0);
  return out.found;
}

}  // namespace mocap
