// Design: see identifier.h for the per-frame steps (the temporal path lives in
// identifier_temporal.cpp). Body states within one frame: kPending (needs a full
// search), kWarm (accepted by the temporal path), kDone (settled: found or not). The
// occupancy of FramePoints carries "points already taken". The bodies awaiting the
// conflict resolution are kept in a compact list, so that a frame in which the temporal
// path took most bodies does not scan all of them in every round.
#include "identify/identifier.h"

#include <algorithm>
#include <cmath>
#include <limits>

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
      motion_(config),
      frame_(config.max_points, config.cameras),
      search_(config, marker_diameter_mm),
      gate_(config),
      tracks_(models_.size()),
      results_(models_.size()),
      state_(models_.size(), kPending),
      gated_(models_.size(), 0),
      pending_(models_.size(), 0) {
  for (const auto& m : models_) max_pair_mm_ = std::max(max_pair_mm_, m.max_pair_mm);
}

void Identifier::reset() noexcept {
  for (auto& tr : tracks_) tr = Track{};
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

void Identifier::release_points(const MarkerPoints& pm, int k) noexcept {
  for (int c = 0; c < k; ++c) {
    const int p = pm[static_cast<std::size_t>(c)];
    if (p >= 0) frame_.release(p);
  }
}

void Identifier::full_search(int body) noexcept {
  SearchStats st;
  SearchResult& r = results_[static_cast<std::size_t>(body)];
  search_.run(models_[static_cast<std::size_t>(body)], frame_, r, st);
  ++counters_.full_searches;
  if (st.node_limit_hit) ++counters_.node_limit_hits;
  if (r.found) settle(body, config_.min_markers, r);
}

bool Identifier::settle(int body, int min_m, SearchResult& r) noexcept {
  const TargetModel& model = models_[static_cast<std::size_t>(body)];
  ConsistencyGate::Stats gs;
  if (!gate_.enforce(model, frame_, min_m, r, gs)) {
    if (gs.partial_reject) {
      ++counters_.partial_rejects;
    } else {
      ++counters_.consistency_rejects;
    }
    return false;
  }
  counters_.outlier_markers += static_cast<std::uint64_t>(gs.dropped);
  counters_.partial_excluded += static_cast<std::uint64_t>(gs.partial_excluded);
  // The rival only matters if it is itself consistent (after its own outliers are dropped).
  if (gate_.enabled() && std::isfinite(r.rival_score)) {
    SearchResult rival;
    rival.found = true;
    rival.point_of_marker = r.rival_point_of_marker;
    ConsistencyGate::Stats rival_stats;
    r.rival_score = gate_.enforce(model, frame_, min_m, rival, rival_stats)
                        ? rival.score
                        : std::numeric_limits<double>::infinity();
  }
  return true;
}

// Two warm bodies sharing a point (or a blob) trust neither prior. Linear in the bodies:
// every warm body takes its points, then a body holding a point (or blob) taken twice
// gives its points back and falls back to the full search.
void Identifier::resolve_warm_conflicts() noexcept {
  const int nb = body_count();
  auto& st = state_;
  for (int b = 0; b < nb; ++b)
    if (st[static_cast<std::size_t>(b)] == kWarm)
      acquire_points(results_[static_cast<std::size_t>(b)].point_of_marker,
                     models_[static_cast<std::size_t>(b)].k);
  for (int b = 0; b < nb; ++b) {
    if (st[static_cast<std::size_t>(b)] != kWarm) continue;
    const auto& pm = results_[static_cast<std::size_t>(b)].point_of_marker;
    for (int c = 0; c < models_[static_cast<std::size_t>(b)].k; ++c) {
      const int p = pm[static_cast<std::size_t>(c)];
      if (p >= 0 && frame_.uses(p) > 1) {
        st[static_cast<std::size_t>(b)] = kWarmConflict;
        break;
      }
    }
  }
  for (int b = 0; b < nb; ++b) {
    auto& s = st[static_cast<std::size_t>(b)];
    if (s == kWarmConflict) {
      release_points(results_[static_cast<std::size_t>(b)].point_of_marker,
                     models_[static_cast<std::size_t>(b)].k);
      s = kPending;
      ++counters_.warm_fallbacks;
    } else if (s == kWarm) {
      s = kFoundWarm;
      ++counters_.warm_accepted;
      if (gated_[static_cast<std::size_t>(b)]) ++counters_.continuity_resolved;
    }
  }
}

// Steps 2-4 of identify() over the compact list of pending bodies.
void Identifier::resolve_pending(std::int64_t t_ns) noexcept {
  auto st = [this](int b) -> std::uint8_t& { return state_[static_cast<std::size_t>(b)]; };
  auto res = [this](int b) -> SearchResult& { return results_[static_cast<std::size_t>(b)]; };
  auto kof = [this](int b) { return models_[static_cast<std::size_t>(b)].k; };
  pending_count_ = 0;
  for (int b = 0; b < body_count(); ++b) {
    if (st(b) != kPending) continue;
    full_search(b);
    if (res(b).found) {
      pending_[static_cast<std::size_t>(pending_count_++)] = static_cast<std::int16_t>(b);
    } else {
      st(b) = kDone;
    }
  }
  const double ratio = config_.ambiguity_ratio;
  while (pending_count_ > 0) {
    // A pending solution (or its rival) that lost points to an accepted body: search again.
    int best_slot = -1;
    for (int i = 0; i < pending_count_;) {
      const int b = pending_[static_cast<std::size_t>(i)];
      const bool rival = std::isfinite(res(b).rival_score);
      if (!points_available(res(b).point_of_marker, kof(b)) ||
          (rival && !points_available(res(b).rival_point_of_marker, kof(b)))) {
        ++counters_.conflict_researches;
        full_search(b);
      }
      if (!res(b).found) {  // nothing left for it: settled, off the list
        st(b) = kDone;
        pending_[static_cast<std::size_t>(i)] =
            pending_[static_cast<std::size_t>(--pending_count_)];
        continue;
      }
      if (res(b).unique(ratio) &&
          (best_slot < 0 ||
           res(b).score < res(pending_[static_cast<std::size_t>(best_slot)]).score))
        best_slot = i;
      ++i;
    }
    if (best_slot < 0) {
      // Only ambiguous bodies remain, and no acceptance can change them any more.
      for (int i = 0; i < pending_count_; ++i) {
        ++counters_.ambiguous_rejects;
        st(pending_[static_cast<std::size_t>(i)]) = kDone;
      }
      pending_count_ = 0;
      break;
    }
    const int best = pending_[static_cast<std::size_t>(best_slot)];
    pending_[static_cast<std::size_t>(best_slot)] =
        pending_[static_cast<std::size_t>(--pending_count_)];
    // 4. Speed limits: a jump beyond them invalidates the body's track. The solution
    // at hand is a cold one (a fresh full search of this frame) and unambiguous (unique
    // at ambiguity_ratio, consistent), so the body is re-acquired ("booted") from it in
    // this same frame instead of being lost until the next one.
    Track& tr = tracks_[static_cast<std::size_t>(best)];
    const TargetModel& model = models_[static_cast<std::size_t>(best)];
    if (!motion_.within_limits(tr, res(best).T_world_body,
                               motion_.pose_noise(model, res(best).point_of_marker), t_ns, model)) {
      ++counters_.velocity_rejects;
      ++counters_.jump_reboots;
      tr = Track{};
    }
    acquire_points(res(best).point_of_marker, kof(best));
    st(best) = kFound;
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
  // 1. Temporal path, then conflicts between warm bodies.
  for (int b = 0; b < nb; ++b) {
    state_[static_cast<std::size_t>(b)] = kPending;
    gated_[static_cast<std::size_t>(b)] = 0;
    const Track& tr = tracks_[static_cast<std::size_t>(b)];
    if (!config_.temporal || !tr.valid) continue;
    const double age_s = static_cast<double>(timestamp_ns - tr.t_last_ns) * 1e-9;
    if (!(age_s <= config_.max_prior_age_s)) continue;
    if (temporal_match(b, timestamp_ns)) {
      state_[static_cast<std::size_t>(b)] = kWarm;
    } else {
      ++counters_.warm_fallbacks;
    }
  }
  resolve_warm_conflicts();
  // 2. Full search of the others, 3. conflicts resolved by score, 4. speed limits.
  resolve_pending(timestamp_ns);

  // Output and tracks.
  out.count = nb;
  out.found = 0;
  for (int b = 0; b < nb; ++b) {
    BodyPose& bp = out.bodies[static_cast<std::size_t>(b)];
    bp = BodyPose{};
    bp.point_index_of_marker.fill(-1);
    const std::uint8_t s = state_[static_cast<std::size_t>(b)];
    if (s != kFound && s != kFoundWarm) continue;
    const SearchResult& r = results_[static_cast<std::size_t>(b)];
    bp.found = true;
    bp.from_prior = s == kFoundWarm;
    bp.T_world_body = r.T_world_body;
    bp.markers = r.m;
    bp.rms_mm = r.rms_mm;
    bp.score = r.score;
    bp.point_index_of_marker = r.point_of_marker;
    ++out.found;
    Track& tr = tracks_[static_cast<std::size_t>(b)];
    // The last pose is a velocity reference only while it is a usable prior itself.
    tr.has_prev = tr.valid && static_cast<double>(timestamp_ns - tr.t_last_ns) * 1e-9 <=
                                  config_.max_prior_age_s;
    tr.T_prev = tr.T_last;
    tr.t_prev_ns = tr.t_last_ns;
    tr.noise_prev = tr.noise_last;
    tr.noise_last = motion_.pose_noise(models_[static_cast<std::size_t>(b)], r.point_of_marker);
    tr.valid = true;
    tr.T_last = r.T_world_body;
    tr.t_last_ns = timestamp_ns;
  }
  counters_.bodies_found += static_cast<std::uint64_t>(out.found);
  frame_.release_all();
  return out.found == nb;
}

}  // namespace mocap
