// Design: setup-time validation of the identification configuration and construction
// of the precomputed target models (see target_model.h).
#include "identify/target_model.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

namespace mocap {
namespace {
std::string num(double v) {
  char buf[64];
  std::snprintf(buf, sizeof(buf), "%g", v);
  return buf;
}
}  // namespace

Expected<void> validate_config(const IdentifyConfig& c) {
  const std::string f = "identify";
  if (!(c.t_mm > 0.0) || !std::isfinite(c.t_mm))
    return make_error(f, "t_mm", "must be > 0, got " + num(c.t_mm));
  if (c.best_pairs < 1 || c.best_pairs > kMaxBestPairs)
    return make_error(f, "best_pairs",
                      "must be in [1, " + std::to_string(kMaxBestPairs) + "], got " +
                          std::to_string(c.best_pairs));
  if (!(c.score_base >= 1.0) || !std::isfinite(c.score_base))
    return make_error(f, "score_base", "must be >= 1, got " + num(c.score_base));
  if (c.min_markers < 3 || c.min_markers > kMaxMarkers)
    return make_error(f, "min_markers",
                      "must be in [3, " + std::to_string(kMaxMarkers) + "], got " +
                          std::to_string(c.min_markers));
  if (!(c.residual_floor_mm >= 0.0) || !std::isfinite(c.residual_floor_mm))
    return make_error(f, "residual_floor_mm", "must be >= 0, got " + num(c.residual_floor_mm));
  if (c.max_points < 3 || c.max_points > kMaxPoints)
    return make_error(
        f, "max_points",
        "must be in [3, " + std::to_string(kMaxPoints) + "], got " + std::to_string(c.max_points));
  if (c.cameras < 1 || c.cameras > kMaxCameras)
    return make_error(
        f, "cameras",
        "must be in [1, " + std::to_string(kMaxCameras) + "], got " + std::to_string(c.cameras));
  if (!(c.point_sigma_mm >= 0.0) || !std::isfinite(c.point_sigma_mm))
    return make_error(f, "point_sigma_mm", "must be >= 0, got " + num(c.point_sigma_mm));
  if (!std::isfinite(c.partial_sigma_mm) ||
      !(c.partial_sigma_mm == 0.0 || c.partial_sigma_mm >= c.point_sigma_mm))
    return make_error(f, "partial_sigma_mm",
                      "must be 0 or >= point_sigma_mm (" + num(c.point_sigma_mm) + "), got " +
                          num(c.partial_sigma_mm));
  if (!(c.consistency_confidence >= 0.99 && c.consistency_confidence <= 0.999999))
    return make_error(f, "consistency_confidence",
                      "must be in [0.99, 0.999999], got " + num(c.consistency_confidence));
  if (c.min_whole_markers < 0 || c.min_whole_markers > kMaxMarkers)
    return make_error(f, "min_whole_markers",
                      "must be in [0, " + std::to_string(kMaxMarkers) + "], got " +
                          std::to_string(c.min_whole_markers));
  if (std::isnan(c.ambiguity_ratio)) return make_error(f, "ambiguity_ratio", "is NaN");
  if (c.max_search_nodes < 1) return make_error(f, "max_search_nodes", "must be >= 1");
  if (!(c.warm_gate_mm > 0.0) || !std::isfinite(c.warm_gate_mm))
    return make_error(f, "warm_gate_mm", "must be > 0, got " + num(c.warm_gate_mm));
  if (c.warm_min_markers < c.min_markers || c.warm_min_markers > kMaxMarkers)
    return make_error(f, "warm_min_markers",
                      "must be in [min_markers, " + std::to_string(kMaxMarkers) + "], got " +
                          std::to_string(c.warm_min_markers));
  if (!(c.max_prior_age_s > 0.0))
    return make_error(f, "max_prior_age_s", "must be > 0, got " + num(c.max_prior_age_s));
  if (std::isnan(c.max_speed_mm_per_s)) return make_error(f, "max_speed_mm_per_s", "is NaN");
  if (!(c.max_acceleration_mm_per_s2 >= 0.0))
    return make_error(f, "max_acceleration_mm_per_s2",
                      "must be >= 0 (0: derived from the speed limits), got " +
                          num(c.max_acceleration_mm_per_s2));
  if (std::isnan(c.max_angular_speed_deg_per_s))
    return make_error(f, "max_angular_speed_deg_per_s", "is NaN");
  return {};
}

Expected<TargetModel> make_target_model(const MarkerTarget& target, const IdentifyConfig& config,
                                        const std::string& where) {
  const std::string f = "targets";
  const int k = static_cast<int>(target.markers_body.size());
  if (k < config.min_markers)
    return make_error(f, where,
                      "has " + std::to_string(k) +
                          " markers, the search needs at least min_markers = " +
                          std::to_string(config.min_markers));
  if (k > kMaxMarkers)
    return make_error(f, where,
                      "has " + std::to_string(k) + " markers, at most " +
                          std::to_string(kMaxMarkers) + " are supported");
  TargetModel model;
  model.name = target.name;
  model.k = k;
  for (int a = 0; a < k; ++a) {
    const Vec3& p = target.markers_body[static_cast<std::size_t>(a)];
    if (!p.allFinite())
      return make_error(f, where, "marker " + std::to_string(a) + " is not finite");
    model.M_body[static_cast<std::size_t>(a)] = p;
  }
  model.min_pair_mm = 1e300;
  for (int a = 0; a < k; ++a) {
    for (int b = a + 1; b < k; ++b) {
      const double d =
          (model.M_body[static_cast<std::size_t>(a)] - model.M_body[static_cast<std::size_t>(b)])
              .norm();
      if (!(d > config.t_mm))
        return make_error(f, where,
                          "markers " + std::to_string(a) + " and " + std::to_string(b) + " are " +
                              num(d) + " mm apart, not more than t = " + num(config.t_mm) + " mm");
      model.dist_mm[static_cast<std::size_t>(a)][static_cast<std::size_t>(b)] = d;
      model.dist_mm[static_cast<std::size_t>(b)][static_cast<std::size_t>(a)] = d;
      model.pairs_sorted.push_back(
          ModelPair{d, static_cast<std::int8_t>(a), static_cast<std::int8_t>(b)});
      model.max_pair_mm = std::max(model.max_pair_mm, d);
      model.min_pair_mm = std::min(model.min_pair_mm, d);
    }
  }
  std::sort(model.pairs_sorted.begin(), model.pairs_sorted.end(),
            [](const ModelPair& x, const ModelPair& y) { return x.d_mm < y.d_mm; });
  model.score_factor[0] = 0.0;
  for (int m = 1; m <= k; ++m)
    model.score_factor[static_cast<std::size_t>(m)] = std::pow(config.score_base, k - m) / m;
  return model;
}

}  // namespace mocap
