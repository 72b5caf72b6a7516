// Design: see identifier.h for the per-frame steps. Body states within one frame:
// kPending (needs a full search), kWarm (accepted by the temporal path), kDone (settled:
// found or not). The occupancy of FramePoints carries "points already taken".
#include "identify/identifier.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "core/units.h"
#include "identify/rigid_fit.h"

namespace mocap {
namespace {
enum : std::uint8_t { kPending, kWarm, kWarmConflict, kDone, kFound, kFoundWarm };
}  // namespace

Expected<Identifier> Identifier::create(const TargetSet& targets, const IdentifyConfig& config) {
  if (auto ok = validate_config(config); !ok) return ok.error();
  // No body (empty targets): identify() finds nothing; the tracker reports 3D points
  // only (`mocap record` / `mocap preview` before any target exists).
  if (static_cast<int>(targets.bodies.size()) > kMaxBodies)
    return make_error("targets", "bodies",
                      std::to_string(targets.bodies.size()) + " bodies, at most " +
                          std::to_string(kMaxBodies) + " are supported");
  std::vector<TargetModel> models;
  for (std::size_t b = 0; b < targets.bodies.size(); ++b) {
    const std::string where = "bodies[" + std::to_string(b) + "] '" + targets.bodies[b].name + "'";
    auto model = make_target_model(targets.bodies[b], config, where);
    if (!model) return model.error();
    models.push_back(std::move(*model));
  }
  Identifier id(config, std::move(models), targets.marker_diameter_mm);
  id.ambiguities_ = find_ambiguities(id.models_, config);
  for (const auto& f : id.ambiguities_) id.warnings_.push_back(f.message);
  if (config.ambiguity_policy == AmbiguityPolicy::kReject && !id.warnings_.empty())
    return Error{id.warnings_.front()};
  return id;
}

Identifier::Identifier(const IdentifyConfig& config, std::vector<TargetModel> models,
                       double marker_diameter_mm)
    : config_(config),
      models_(std::move(models)),
      frame_(config.max_points),
      search_(config, marker_diameter_mm),
      gate_(config),
      tracks_(models_.size()),
      results_(models_.size()),
      state_(models_.size(), kPending) {
  for (const auto& m : models_) max_pair_mm_ = std::max(max_pair_mm_, m.max_pair_mm);
}

void Identifier::reset() noexcept {
  for (auto& tr : tracks_) tr = Track{};
}

Iso3 Identifier::predict(const Track& tr, std::int64_t t_ns) const noexcept {
  if (config_.motion_model == MotionModel::kConstantPose || !tr.has_prev ||
      tr.t_last_ns <= tr.t_prev_ns)
    return tr.T_last;
  const double r =
      static_cast<double>(t_ns - tr.t_last_ns) / static_cast<double>(tr.t_last_ns - tr.t_prev_ns);
  const Eigen::AngleAxisd dR(tr.T_last.linear() * tr.T_prev.linear().transpose());
  Iso3 T = Iso3::Identity();
  T.linear() = Eigen::AngleAxisd(dR.angle() * r, dR.axis()).toRotationMatrix() * tr.T_last.linear();
  T.translation() =
      tr.T_last.translation() + r * (tr.T_last.translation() - tr.T_prev.translation());
  return T;
}

bool Identifier::within_speed_limits(const Track& tr, const Iso3& T,
                                     std::int64_t t_ns) const noexcept {
  if (!tr.valid) return true;
  const double dt_s = static_cast<double>(t_ns - tr.t_last_ns) * 1e-9;
  if (!(dt_s > 0.0)) return true;
  if (config_.max_speed_mm_per_s > 0.0 &&
      (T.translation() - tr.T_last.translation()).norm() / dt_s > config_.max_speed_mm_per_s)
    return false;
  if (config_.max_angular_speed_deg_per_s > 0.0) {
    const Eigen::AngleAxisd dR(T.linear() * tr.T_last.linear().transpose());
    if (std::abs(dR.angle()) * kDegPerRad / dt_s > config_.max_angular_speed_deg_per_s)
      return false;
  }
  return true;
}

bool Identifier::warm_match(int body, const Iso3& T_pred, SearchResult& out) noexcept {
  const TargetModel& model = models_[static_cast<std::size_t>(body)];
  out = SearchResult{};
  out.point_of_marker.fill(-1);
  const double gate = std::min(warm_gate_mm_, 0.5 * model.min_pair_mm);
  const double t2 = config_.t_mm * config_.t_mm;
  const int n = frame_.size();
  FitPoints src(3, kMaxMarkers), dst(3, kMaxMarkers);
  Iso3 T = T_pred;
  int m = 0;
  RigidFit fit;
  // Pass 0: gate around the prediction; pass 1: radius min(t, gate) around the refit.
  for (int pass = 0; pass < 2; ++pass) {
    const double r = pass == 0 ? gate : std::min(config_.t_mm, gate);
    const int m_before = m;
    for (int c = 0; c < model.k; ++c) {
      const auto cs = static_cast<std::size_t>(c);
      if (out.point_of_marker[cs] >= 0) continue;
      const Vec3 x = T * model.M_body[cs];
      int hits = 0;
      int hit = -1;
      for (int p = 0; p < n; ++p) {
        if ((frame_.X(p) - x).squaredNorm() < r * r && frame_.available(p)) {
          ++hits;
          hit = p;
        }
      }
      if (hits > 1) return false;  // not unique: let the full search decide
      if (hits == 0) continue;
      for (int s = 0; s < model.k; ++s) {
        const int q = out.point_of_marker[static_cast<std::size_t>(s)];
        if (q >= 0 && (q == hit || frame_.exclusive(q, hit))) return false;
      }
      out.point_of_marker[cs] = static_cast<std::int16_t>(hit);
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
  ConsistencyGate::Stats gs;
  const bool ok = gate_.enforce(model, frame_, config_.warm_min_markers, out, gs);
  counters_.outlier_markers += static_cast<std::uint64_t>(gs.dropped);
  counters_.partial_excluded += static_cast<std::uint64_t>(gs.partial_excluded);
  return ok;
}

bool Identifier::points_available(const MarkerPoints& pm, int k) const noexcept {
  for (int c = 0; c < k; ++c) {
    const int p = pm[static_cast<std::size_t>(c)];
    if (p >= 0 && !frame_.available(p)) return false;
  }
  return true;
}

void Identifier::acquire_points(const MarkerPoints& pm, int k) noexcept {
  for (int c = 0; c < k; ++c) {
    const int p = pm[static_cast<std::size_t>(c)];
    if (p >= 0) frame_.acquire(p);
  }
}

bool Identifier::conflicts(const SearchResult& a, int ka, const SearchResult& b,
                           int kb) const noexcept {
  for (int i = 0; i < ka; ++i) {
    const int p = a.point_of_marker[static_cast<std::size_t>(i)];
    if (p < 0) continue;
    for (int j = 0; j < kb; ++j) {
      const int q = b.point_of_marker[static_cast<std::size_t>(j)];
      if (q >= 0 && (p == q || frame_.exclusive(p, q))) return true;
    }
  }
  return false;
}

void Identifier::full_search(int body) noexcept {
  SearchStats st;
  search_.run(models_[static_cast<std::size_t>(body)], frame_,
              results_[static_cast<std::size_t>(body)], st);
  ++counters_.full_searches;
  if (st.node_limit_hit) ++counters_.node_limit_hits;
  SearchResult& r = results_[static_cast<std::size_t>(body)];
  if (!r.found) return;
  const TargetModel& model = models_[static_cast<std::size_t>(body)];
  ConsistencyGate::Stats gs;
  if (!gate_.enforce(model, frame_, config_.min_markers, r, gs)) {
    if (gs.partial_reject) {
      ++counters_.partial_rejects;
    } else {
      ++counters_.consistency_rejects;
    }
    return;
  }
  counters_.outlier_markers += static_cast<std::uint64_t>(gs.dropped);
  counters_.partial_excluded += static_cast<std::uint64_t>(gs.partial_excluded);
  // The rival only matters if it is itself consistent (after its own outliers are dropped).
  if (gate_.enabled() && std::isfinite(r.rival_score)) {
    SearchResult rival;
    rival.found = true;
    rival.point_of_marker = r.rival_point_of_marker;
    ConsistencyGate::Stats rival_stats;
    r.rival_score = gate_.enforce(model, frame_, config_.min_markers, rival, rival_stats)
                        ? rival.score
                        : std::numeric_limits<double>::infinity();
  }
}

bool Identifier::identify(const MeasuredPoint* pts, int n, std::int64_t timestamp_ns,
                          BodyPoses& out) noexcept {
  ++counters_.frames;
  const int nb = body_count();
  const FramePoints::LoadStats ls = frame_.load(pts, n, max_pair_mm_ + config_.t_mm);
  counters_.point_overflow += static_cast<std::uint64_t>(ls.dropped);
  counters_.invalid_points += static_cast<std::uint64_t>(ls.invalid);

  bool bad_time = false;
  for (const Track& tr : tracks_) bad_time = bad_time || (tr.valid && timestamp_ns <= tr.t_last_ns);
  if (bad_time) {
    ++counters_.bad_timestamps;
    reset();
  }
  // Per-body state of this frame (kPending ... kFoundWarm).
  auto st = [this](int b) -> std::uint8_t& { return state_[static_cast<std::size_t>(b)]; };
  auto res = [this](int b) -> SearchResult& { return results_[static_cast<std::size_t>(b)]; };
  auto trk = [this](int b) -> Track& { return tracks_[static_cast<std::size_t>(b)]; };
  auto kof = [this](int b) { return models_[static_cast<std::size_t>(b)].k; };

  // 1. Temporal path.
  for (int b = 0; b < nb; ++b) {
    st(b) = kPending;
    const Track& tr = trk(b);
    if (!config_.temporal || !tr.valid) continue;
    const double age_s = static_cast<double>(timestamp_ns - tr.t_last_ns) * 1e-9;
    if (!(age_s <= config_.max_prior_age_s)) continue;
    // The prediction error grows with the time since the body was last seen: the gate
    // scales with that age relative to the interval the prior was measured over.
    const double interval_s =
        tr.has_prev ? static_cast<double>(tr.t_last_ns - tr.t_prev_ns) * 1e-9 : age_s;
    warm_gate_mm_ =
        config_.warm_gate_mm * (interval_s > 0.0 && age_s > interval_s ? age_s / interval_s : 1.0);
    if (warm_match(b, predict(tr, timestamp_ns), res(b)) &&
        within_speed_limits(tr, res(b).T_world_body, timestamp_ns)) {
      st(b) = kWarm;
    } else {
      ++counters_.warm_fallbacks;
    }
  }
  // Two warm bodies sharing a point (or a blob): neither prior is trusted.
  for (int a = 0; a < nb; ++a) {
    for (int b = a + 1; b < nb; ++b) {
      const bool wa = st(a) == kWarm || st(a) == kWarmConflict;
      const bool wb = st(b) == kWarm || st(b) == kWarmConflict;
      if (wa && wb && conflicts(res(a), kof(a), res(b), kof(b))) {
        st(a) = kWarmConflict;
        st(b) = kWarmConflict;
      }
    }
  }
  for (int b = 0; b < nb; ++b) {
    if (st(b) == kWarmConflict) {
      st(b) = kPending;
      ++counters_.warm_fallbacks;
    } else if (st(b) == kWarm) {
      acquire_points(res(b).point_of_marker, kof(b));
      st(b) = kFoundWarm;
      ++counters_.warm_accepted;
    }
  }
  // 2. Full search of the others, 3. conflicts resolved by score.
  for (int b = 0; b < nb; ++b)
    if (st(b) == kPending) full_search(b);
  const double ratio = config_.ambiguity_ratio;
  for (;;) {
    // A pending solution (or its rival) that lost points to an accepted body: search again.
    for (int b = 0; b < nb; ++b) {
      if (st(b) != kPending || !res(b).found) continue;
      const bool rival = std::isfinite(res(b).rival_score);
      if (!points_available(res(b).point_of_marker, kof(b)) ||
          (rival && !points_available(res(b).rival_point_of_marker, kof(b)))) {
        ++counters_.conflict_researches;
        full_search(b);
      }
    }
    // Accept the best-scoring unambiguous pending body.
    int best = -1;
    for (int b = 0; b < nb; ++b) {
      if (st(b) != kPending) continue;
      if (!res(b).found) {
        st(b) = kDone;
        continue;
      }
      if (!res(b).unique(ratio)) continue;
      if (best < 0 || res(b).score < res(best).score) best = b;
    }
    if (best < 0) {
      // Only ambiguous bodies remain, and no acceptance can change them any more.
      for (int b = 0; b < nb; ++b) {
        if (st(b) != kPending) continue;
        ++counters_.ambiguous_rejects;
        st(b) = kDone;
      }
      break;
    }
    // 4. Speed limits: a jump beyond them invalidates the body's track. The solution
    // at hand is a cold one (a fresh full search of this frame) and unambiguous (unique
    // at ambiguity_ratio, consistent), so the body is re-acquired ("booted") from it in
    // this same frame instead of being lost until the next one.
    if (!within_speed_limits(trk(best), res(best).T_world_body, timestamp_ns)) {
      ++counters_.velocity_rejects;
      ++counters_.jump_reboots;
      trk(best) = Track{};
    }
    acquire_points(res(best).point_of_marker, kof(best));
    st(best) = kFound;
  }

  // Output and tracks.
  out.count = nb;
  out.found = 0;
  for (int b = 0; b < nb; ++b) {
    BodyPose& bp = out.bodies[static_cast<std::size_t>(b)];
    bp = BodyPose{};
    bp.point_index_of_marker.fill(-1);
    if (st(b) != kFound && st(b) != kFoundWarm) continue;
    const SearchResult& r = res(b);
    bp.found = true;
    bp.from_prior = st(b) == kFoundWarm;
    bp.T_world_body = r.T_world_body;
    bp.markers = r.m;
    bp.rms_mm = r.rms_mm;
    bp.score = r.score;
    bp.point_index_of_marker = r.point_of_marker;
    ++out.found;
    Track& tr = trk(b);
    tr.has_prev = tr.valid;
    tr.T_prev = tr.T_last;
    tr.t_prev_ns = tr.t_last_ns;
    tr.valid = true;
    tr.T_last = r.T_world_body;
    tr.t_last_ns = timestamp_ns;
  }
  counters_.bodies_found += static_cast<std::uint64_t>(out.found);
  frame_.release_all();
  return out.found == nb;
}

}  // namespace mocap
