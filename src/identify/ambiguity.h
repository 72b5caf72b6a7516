// Design: load-time detection of targets that the search can confuse. For every pair of
// targets (A, B), and for every target with itself under a non-identity correspondence,
// we look for the largest set of >= min_markers markers of A that a proper rigid motion
// maps onto distinct markers of B with every residual < t: those markers seen alone (the
// rest occluded) are indistinguishable. Mirror-image targets (e.g. left/right limbs) are
// covered: all their triangles are congruent, so they are reported with m >= 3 (more when
// they have coplanar subsets); a symmetric target is reported against itself.
// Method: every triangle of A against every ordered triangle of B with matching side
// lengths (within t), Umeyama fit, then greedy growth by nearest markers within t.
#pragma once

#include <string>
#include <vector>

#include "identify/target_model.h"

namespace mocap {

struct AmbiguityFinding {
  int body_a = 0;
  int body_b = 0;       // == body_a: the target is self-similar (symmetric)
  int markers = 0;      // markers of A that align with markers of B
  double rms_mm = 0.0;  // RMS residual of that alignment
  std::string message;  // one line naming the bodies, m and the RMS
};

std::vector<AmbiguityFinding> find_ambiguities(const std::vector<TargetModel>& models,
                                               const IdentifyConfig& config);

}  // namespace mocap
