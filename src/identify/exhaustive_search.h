// Design: the reference solution of Eq. 1 without the best-pairs heuristic: every
// injective assignment of measured points to model markers (or none) is enumerated and
// the feasible one (m >= min_markers, every pair discrepancy < t, no two mutually
// exclusive points, every Umeyama residual < t) with the lowest score wins. Exponential:
// for tests and as the benchmark baseline on small sizes only. Allocation-free too.
#pragma once

#include "identify/frame_points.h"
#include "identify/target_search.h"

namespace mocap {

// Same result conventions as TargetSearch::run (ties: larger m).
bool exhaustive_search(const TargetModel& model, FramePoints& frame, const IdentifyConfig& config,
                       SearchResult& out) noexcept;

}  // namespace mocap
