// Design: the immutable, precomputed form of one marker target used by the search:
// markers in the body frame, the full pair-distance table, the pair distances sorted
// ascending (for the merge/binary search against the measured pair distances) and the
// score factor table base^(k-m)/m. Built once at setup from targets.yaml's MarkerTarget.
#pragma once

#include <array>
#include <string>
#include <vector>

#include "core/expected.h"
#include "formats/targets_yaml.h"
#include "identify/identify_types.h"

namespace mocap {

struct ModelPair {
  double d_mm = 0.0;
  std::int8_t a = 0;
  std::int8_t b = 0;
};

struct TargetModel {
  std::string name;
  int k = 0;  // number of markers
  std::array<Vec3, kMaxMarkers> M_body{};
  std::array<std::array<double, kMaxMarkers>, kMaxMarkers> dist_mm{};
  std::vector<ModelPair> pairs_sorted;  // k(k-1)/2 pairs, ascending distance
  double max_pair_mm = 0.0;
  double min_pair_mm = 0.0;
  std::array<double, kMaxMarkers + 1> score_factor{};  // base^(k-m)/m for m = 1..k
};

// Validates the target against the capacities and the configuration; `where` prefixes
// errors ("targets: bodies[2] 'arm'").
Expected<TargetModel> make_target_model(const MarkerTarget& target, const IdentifyConfig& config,
                                        const std::string& where);

// One-line error if the configuration is unusable ("identify: t_mm: must be > 0").
Expected<void> validate_config(const IdentifyConfig& config);

}  // namespace mocap
