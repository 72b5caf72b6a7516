// Design: reader/writer of the spec's targets.yaml (rigid marker targets, one per
// body, markers in the body's own frame, mm). Load-time validation: at least one body,
// unique non-empty names, >= 3 markers per body, finite coordinates, no two markers of
// a body closer than the marker diameter (default 12 mm when the key is absent).
#pragma once

#include <string>
#include <vector>

#include "core/expected.h"
#include "core/types.h"

namespace mocap {

struct MarkerTarget {
  std::string name;
  std::vector<Vec3> markers_body;  // mm, body frame
};

struct TargetSet {
  double marker_diameter_mm = 12.0;
  std::vector<MarkerTarget> bodies;

  // Index of the body with this name, or -1.
  int index_of(const std::string& name) const noexcept;
};

Expected<TargetSet> load_targets(const std::string& path);
Expected<void> save_targets(const std::string& path, const TargetSet& targets);

}  // namespace mocap
