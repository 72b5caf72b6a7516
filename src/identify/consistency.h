// Design: the statistical consistency test of an identified solution, applied after the
// paper's search (and after the temporal path) and before a body is accepted.
//
// The paper's gate t (5 mm) bounds every pair discrepancy and residual; it is wide on
// purpose, so that the search survives noise and calibration error. It is far wider than
// the 3D noise of a working system (0.02-0.3 mm), so a wrong correspondence (a stray or
// ghost point completing a triangle within t) or a marker whose image is partly occluded
// (its centroid biased by 1-3 mm) still passes it. Such a fit has residuals many sigma
// above the noise: with a per-coordinate 3D noise sigma, the least-squares residual of a
// correct m-marker fit follows sigma^2 * chi^2 with 3m - 6 degrees of freedom.
//
// The test: sum_sq <= sigma^2 * chi2_quantile(3m - 6, confidence) (m = 3 gets 3 degrees
// of freedom, its 9 noise coordinates minus the 6 of the pose). With more than min_m
// markers, each marker is also tested alone (a single biased marker is diluted in the
// global sum): the drop of the sum of squares when it leaves the fit (leave-one-out)
// follows sigma^2 * chi^2 with 3 degrees of freedom. When either test fails, the
// marker whose removal lowers the sum of squares the most is dropped and the tests
// repeated; a solution that cannot pass the global test with min_m markers is rejected. Dropped
// markers free their points for other bodies. sigma = 0 disables the test (the paper's behaviour).
//
// Partial markers (MeasuredPoint::partial: the image does not look like a whole marker)
// are identified like the others, but while at least 3 whole markers are matched the
// pose is fitted (and tested) on the whole markers only; a partial marker stays matched
// when it agrees with that pose within t. When fewer than 3 whole markers are matched
// (and min_whole_markers allows it), or with exclude_partial_markers = false, the partial
// markers join the fit with their own noise partial_sigma_mm: a weighted fit with weights
// (point_sigma / sigma_i)^2, and the sums of squares above are these weighted sums, so the
// chi-square thresholds stay those of point_sigma (residuals normalised per marker).
#pragma once

#include <array>

#include "identify/frame_points.h"
#include "identify/identify_types.h"
#include "identify/target_model.h"
#include "identify/target_search.h"

namespace mocap {

// Upper quantile of the chi-square distribution (Wilson-Hilferty; within 4 % of the exact
// value for dof >= 3 at confidence <= 0.99999). dof >= 1, 0 < confidence < 1.
double chi2_quantile(int dof, double confidence) noexcept;

class ConsistencyGate {
 public:
  ConsistencyGate() = default;
  explicit ConsistencyGate(const IdentifyConfig& config) noexcept;

  bool enabled() const noexcept { return enabled_; }
  // Largest acceptable sum of squared residuals (mm^2) of an m-marker fit.
  double max_sum_sq_mm2(int m) const noexcept {
    return max_sum_sq_mm2_[static_cast<std::size_t>(m)];
  }

  struct Stats {
    int dropped = 0;              // matched markers removed (outliers, disagreeing partials)
    int partial_excluded = 0;     // partial markers kept matched but left out of the fit
    bool partial_reject = false;  // fewer than min_whole_markers whole markers
  };
  // The final fit of `r` (a found solution of `model` among `frame`'s points): whole
  // markers only when possible, outliers dropped until the test passes; refits the pose,
  // residuals and score. Returns false (and clears r.found) when it cannot pass with at
  // least min_m fitted markers. noexcept, allocation-free.
  bool enforce(const TargetModel& model, const FramePoints& frame, int min_m, SearchResult& r,
               Stats& stats) const noexcept;

 private:
  bool enabled_ = false;
  bool exclude_partial_ = true;
  int min_whole_ = 0;
  double partial_weight_ = 1.0;  // (point_sigma / partial_sigma)^2
  double t2_mm2_ = 25.0;
  double floor2_mm2_ = 0.0;
  std::array<double, kMaxMarkers + 1> max_sum_sq_mm2_{};
  double max_drop_sq_mm2_ = 0.0;
};

}  // namespace mocap
