// Design: see consistency.h. The leave-one-out step swaps the candidate column to the
// end, fits the first m-1 columns and swaps it back: no copy, no allocation.
#include "identify/consistency.h"

#include <cmath>
#include <limits>
#include <utility>

#include "identify/rigid_fit.h"

namespace mocap {
namespace {

// Standard normal upper quantile z(p) for 0.98 <= p < 1 (the upper-tail branch of Acklam's
// rational approximation, relative error < 1.2e-9; validate_config bounds p).
double normal_quantile(double p) noexcept {
  const double q = std::sqrt(-2.0 * std::log(1.0 - p));
  constexpr double c[] = {-7.784894002430293e-03, -3.223964580411365e-01, -2.400758277161838e+00,
                          -2.549732539343734e+00, 4.374664141464968e+00,  2.938163982698783e+00};
  constexpr double d[] = {7.784695709041462e-03, 3.224671290700398e-01, 2.445134137142996e+00,
                          3.754408661907416e+00};
  const double num = ((((c[0] * q + c[1]) * q + c[2]) * q + c[3]) * q + c[4]) * q + c[5];
  const double den = (((d[0] * q + d[1]) * q + d[2]) * q + d[3]) * q + 1.0;
  return -num / den;
}

void swap_cols(FitPoints& a, FitPoints& b, FitWeights& w, Eigen::Index i, Eigen::Index j) noexcept {
  if (i == j) return;
  a.col(i).swap(a.col(j));
  b.col(i).swap(b.col(j));
  std::swap(w[static_cast<std::size_t>(i)], w[static_cast<std::size_t>(j)]);
}

}  // namespace

double chi2_quantile(int dof, double confidence) noexcept {
  const double k = static_cast<double>(dof);
  const double z = normal_quantile(confidence);
  const double h = 2.0 / (9.0 * k);
  const double c = 1.0 - h + z * std::sqrt(h);
  return k * c * c * c;
}

ConsistencyGate::ConsistencyGate(const IdentifyConfig& config) noexcept
    : enabled_(config.point_sigma_mm > 0.0),
      exclude_partial_(config.exclude_partial_markers),
      min_whole_(config.min_whole_markers),
      t2_mm2_(config.t_mm * config.t_mm),
      floor2_mm2_(config.residual_floor_mm * config.residual_floor_mm) {
  if (!enabled_) return;
  const double s2 = config.point_sigma_mm * config.point_sigma_mm;
  if (config.partial_sigma_mm > 0.0)
    partial_weight_ = s2 / (config.partial_sigma_mm * config.partial_sigma_mm);
  for (int m = 3; m <= kMaxMarkers; ++m) {
    max_sum_sq_mm2_[static_cast<std::size_t>(m)] =
        s2 * chi2_quantile(3 * m - 6, config.consistency_confidence);
  }
  // Removing one marker removes 3 degrees of freedom from the residual.
  max_drop_sq_mm2_ = s2 * chi2_quantile(3, config.consistency_confidence);
}

bool ConsistencyGate::enforce(const TargetModel& model, const FramePoints& frame, int min_m,
                              SearchResult& r, Stats& stats) const noexcept {
  if (!r.found) return false;
  // Columns: whole markers first, then partial ones.
  FitPoints src(3, kMaxMarkers), dst(3, kMaxMarkers);
  FitWeights w{};
  std::array<std::int8_t, kMaxMarkers> marker_of_col{};
  int m = 0;
  int n_whole = 0;
  for (int pass = 0; pass < 2; ++pass) {
    for (int c = 0; c < model.k; ++c) {
      const int p = r.point_of_marker[static_cast<std::size_t>(c)];
      if (p < 0 || frame.partial(p) != (pass == 1)) continue;
      src.col(m) = model.M_body[static_cast<std::size_t>(c)];
      dst.col(m) = frame.X(p);
      w[static_cast<std::size_t>(m)] = pass == 0 ? 1.0 : partial_weight_;
      marker_of_col[static_cast<std::size_t>(m)] = static_cast<std::int8_t>(c);
      ++m;
    }
    if (pass == 0) n_whole = m;
  }
  // A pose that rests on partial markers needs a redundant fit (at least 4 markers, so
  // that the test below can see a biased one): with 3, every bias passes into the pose.
  if (m < 3 || n_whole < min_whole_ || (n_whole < 3 && m < 4)) {
    stats.partial_reject = m >= 3;
    r.found = false;
    return false;
  }
  int nf = (exclude_partial_ && n_whole >= 3) ? n_whole : m;  // fitted columns [0, nf)
  if (nf == m && !enabled_) return true;                      // the search's fit stands
  auto remove_col = [&](int i) noexcept {                     // column i leaves the solution
    r.point_of_marker[static_cast<std::size_t>(marker_of_col[static_cast<std::size_t>(i)])] = -1;
    std::swap(marker_of_col[static_cast<std::size_t>(i)],
              marker_of_col[static_cast<std::size_t>(m - 1)]);
    swap_cols(src, dst, w, i, m - 1);
    --m;
    ++stats.dropped;
  };
  RigidFit fit = fit_rigid_weighted(src, dst, w, nf);
  while (enabled_) {
    const bool global_ok = fit.sum_sq_mm2 <= max_sum_sq_mm2(nf);
    if (nf <= min_m) {
      if (global_ok) break;
      r.found = false;
      return false;
    }
    // No single marker's drop can exceed the whole sum: a small sum needs no refits.
    if (global_ok && fit.sum_sq_mm2 <= max_drop_sq_mm2_) break;
    // Leave-one-out fits: the drop of the sum of squares when one marker leaves tests that
    // marker alone (one biased marker is diluted in the global sum); the largest drop
    // names the marker to remove.
    int worst = -1;
    RigidFit best_fit;
    best_fit.sum_sq_mm2 = std::numeric_limits<double>::infinity();
    for (int i = 0; i < nf; ++i) {
      swap_cols(src, dst, w, i, nf - 1);
      const RigidFit f = fit_rigid_weighted(src, dst, w, nf - 1);
      swap_cols(src, dst, w, i, nf - 1);
      if (f.sum_sq_mm2 < best_fit.sum_sq_mm2) {
        best_fit = f;
        worst = i;
      }
    }
    if (global_ok && fit.sum_sq_mm2 - best_fit.sum_sq_mm2 <= max_drop_sq_mm2_) break;
    // Move the worst to the end of the fitted range, then out of the solution (the
    // partial column that takes its place at nf - 1 is outside the new range [0, nf - 1)).
    std::swap(marker_of_col[static_cast<std::size_t>(worst)],
              marker_of_col[static_cast<std::size_t>(nf - 1)]);
    swap_cols(src, dst, w, worst, nf - 1);
    --nf;
    remove_col(nf);
    fit = best_fit;
  }
  // Partial markers outside the fit stay matched when they agree with the pose within t.
  for (int i = m - 1; i >= nf; --i) {
    const double r2 = (fit.T_dst_src * Vec3(src.col(i)) - Vec3(dst.col(i))).squaredNorm();
    if (r2 < t2_mm2_) {
      ++stats.partial_excluded;
    } else {
      remove_col(i);
    }
  }
  r.m = m;
  r.sum_sq_mm2 = fit.sum_sq_mm2;
  r.rms_mm = std::sqrt(fit.sum_sq_mm2 / nf);
  r.T_world_body = fit.T_dst_src;
  r.score =
      std::sqrt(fit.sum_sq_mm2 + m * floor2_mm2_) * model.score_factor[static_cast<std::size_t>(m)];
  return true;
}

}  // namespace mocap
