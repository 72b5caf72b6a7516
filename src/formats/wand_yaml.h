// Design: the calibration-object file (wand.yaml, docs/rig_calibration.md): the wand's
// collinear markers as offsets along its axis and, optionally, the L-frame's markers
// in its own (ground) frame. Validation at load: >= 3 strictly increasing wand offsets
// whose spacing pattern is not symmetric (else the wand's two ends could be confused),
// 3..8 L-frame markers, not all collinear. Errors are one line "<file>: key: problem".
#pragma once

#include <string>
#include <vector>

#include "core/expected.h"
#include "core/types.h"

namespace mocap {

struct WandSpec {
  std::vector<double> markers_mm;  // offsets along the axis, strictly increasing, first = 0
  double marker_diameter_mm = 12.0;
  double length_mm() const {
    return markers_mm.empty() ? 0.0 : markers_mm.back() - markers_mm.front();
  }
};

struct LFrameSpec {
  std::vector<Vec3> markers_mm;  // marker centres in the ground frame (Z up)
  double marker_diameter_mm = 12.0;
};

struct CalibrationObjects {
  WandSpec wand;
  bool has_lframe = false;
  LFrameSpec lframe;
};

// Checks a wand description (the rules above); `where` prefixes the error's key.
Expected<void> validate_wand(const WandSpec& wand, const std::string& file);
Expected<void> validate_lframe(const LFrameSpec& lframe, const std::string& file);

Expected<CalibrationObjects> load_calibration_objects(const std::string& path);
Expected<void> save_calibration_objects(const std::string& path, const CalibrationObjects& objects);

}  // namespace mocap
