// Design: the temporal path of Identifier (identifier.h, step 1; the bounds in motion.h).
// For a body with a recent pose: the available points within the gate of each predicted
// marker (its own radius: the prediction's noise differs from marker to marker) come from the grid
// of FramePoints (cost independent of the number of bodies).
//  - One point in every gate and at least warm_min_markers of them: nearest-neighbour
//    match, Umeyama refit, a second pass within min(t, gate) of the refit, residuals < t,
//    consistency test (consistency.h) with warm_min_markers.
//  - Otherwise (two points in some gate, or fewer matched markers), or when that fails:
//    identification by continuity. The paper's Eq. 1 search runs on the gates' points
//    only (TargetSearch gated mode), with its rival pass: a solution is taken when no
//    placement that contradicts it, within the gates, comes within ambiguity_ratio of its
//    score. The gates of one body never overlap (half the smallest marker distance), so
//    the same points can only lie in them under one correspondence: a triangle of a
//    3-marker body that also fits another triangle of its target (or of another target)
//    is decided by the prediction. Two different point sets that both fit within the
//    gates stay ambiguous, and without a prediction nothing is decided here at all (the
//    full search and its ambiguity rule then apply). The consistency test uses
//    min_markers.
// Either way the pose must stay within the speed limits since the body was last seen.
#include <algorithm>
#include <cmath>
#include <limits>

#include "identify/identifier.h"
#include "identify/rigid_fit.h"

namespace mocap {

bool Identifier::temporal_match(int body, std::int64_t t_ns) noexcept {
  const TargetModel& model = models_[static_cast<std::size_t>(body)];
  const Track& tr = tracks_[static_cast<std::size_t>(body)];
  SearchResult& r = results_[static_cast<std::size_t>(body)];
  const Iso3 T_pred = motion_.predict(tr, t_ns);
  std::array<double, kMaxMarkers> gate{};
  motion_.gates_mm(tr, t_ns, model, gate);
  int with = 0;
  bool several = false, overflow = false;
  for (int c = 0; c < model.k; ++c) {
    const auto cs = static_cast<std::size_t>(c);
    const int n = frame_.available_within(T_pred * model.M_body[cs], gate[cs],
                                          cand_.point[cs].data(), MarkerCandidates::kMax);
    cand_.count[cs] = static_cast<std::int8_t>(std::min(n, MarkerCandidates::kMax));
    with += n > 0 ? 1 : 0;
    several = several || n > 1;
    overflow = overflow || n > MarkerCandidates::kMax;
  }
  if (!several && with >= config_.warm_min_markers && nearest_match(body, T_pred, gate, r) &&
      motion_.within_limits(tr, r.T_world_body, motion_.pose_noise(model, r.point_of_marker), t_ns,
                            model))
    return true;
  if (overflow || with < config_.min_markers || !gated_search(body, r)) return false;
  if (!motion_.within_limits(tr, r.T_world_body, motion_.pose_noise(model, r.point_of_marker), t_ns,
                             model))
    return false;
  gated_[static_cast<std::size_t>(body)] = 1;
  return true;
}

bool Identifier::gated_search(int body, SearchResult& r) noexcept {
  SearchStats st;
  search_.run(models_[static_cast<std::size_t>(body)], frame_, r, st, &cand_);
  if (st.node_limit_hit) ++counters_.node_limit_hits;
  if (!r.found || !settle(body, config_.min_markers, r)) return false;
  return r.unique(config_.ambiguity_ratio);
}

bool Identifier::nearest_match(int body, const Iso3& T_pred,
                               const std::array<double, kMaxMarkers>& gate,
                               SearchResult& out) noexcept {
  const TargetModel& model = models_[static_cast<std::size_t>(body)];
  out = SearchResult{};
  out.point_of_marker.fill(-1);
  const double t2 = config_.t_mm * config_.t_mm;
  FitPoints src(3, kMaxMarkers), dst(3, kMaxMarkers);
  Iso3 T = T_pred;
  int m = 0;
  RigidFit fit;
  // Pass 0: the single point of each gate; pass 1: radius min(t, gate) around the refit.
  for (int pass = 0; pass < 2; ++pass) {
    const int m_before = m;
    for (int c = 0; c < model.k; ++c) {
      const auto cs = static_cast<std::size_t>(c);
      if (out.point_of_marker[cs] >= 0) continue;
      std::int16_t hit = -1;
      int hits = 0;
      if (pass == 0) {
        hits = cand_.count[cs];
        if (hits == 1) hit = cand_.point[cs][0];
      } else {
        hits = frame_.available_within(T * model.M_body[cs], std::min(config_.t_mm, gate[cs]), &hit,
                                       1);
      }
      if (hits > 1) return false;  // not unique: the gated search decides
      if (hits == 0) continue;
      for (int s = 0; s < model.k; ++s) {
        const int q = out.point_of_marker[static_cast<std::size_t>(s)];
        if (q >= 0 && (q == hit || frame_.exclusive(q, hit))) return false;
      }
      out.point_of_marker[cs] = hit;
      src.col(m) = model.M_body[cs];
      dst.col(m) = frame_.X(hit);
      ++m;
    }
    if (m < config_.warm_min_markers) return false;
    if (pass == 1 && m == m_before) break;
    fit = fit_rigid(src, dst, m);
    if (!(fit.max_sq_mm2 < t2)) return false;
    T = fit.T_dst_src;
  }
  const double floor2 = config_.residual_floor_mm * config_.residual_floor_mm;
  out.found = true;
  out.m = m;
  out.sum_sq_mm2 = fit.sum_sq_mm2;
  out.rms_mm = std::sqrt(fit.sum_sq_mm2 / m);
  out.score =
      std::sqrt(fit.sum_sq_mm2 + m * floor2) * model.score_factor[static_cast<std::size_t>(m)];
  out.T_world_body = fit.T_dst_src;
  out.rival_score = std::numeric_limits<double>::infinity();
  ConsistencyGate::Stats gs;
  const bool ok = gate_.enforce(model, frame_, config_.warm_min_markers, out, gs);
  counters_.outlier_markers += static_cast<std::uint64_t>(gs.dropped);
  counters_.partial_excluded += static_cast<std::uint64_t>(gs.partial_excluded);
  return ok;
}

}  // namespace mocap
