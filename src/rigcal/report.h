// Design: the calibration quality report: report.yaml (every number of RigCalResult
// that a user or a script checks: reprojection RMS per camera, wand-length error,
// coverage, frames, warnings; per camera of a 2..32-camera rig also its frames used and
// its pose relative to camera 0) and one coverage PNG per camera (half resolution: the
// coverage grid, occupied cells tinted green, each labelled wand marker a white dot).
#pragma once

#include <string>

#include "core/expected.h"
#include "formats/png_writer.h"
#include "rigcal/rig_calibrator.h"

namespace mocap::rigcal {

std::string format_report_yaml(const RigCalResult& result, const RigCalOptions& options);
RgbImage coverage_image(const CameraQuality& quality, const CameraModel& camera, int cols,
                        int rows);
// Writes dir/report.yaml and dir/coverage_<camera>.png (dir created if needed).
Expected<void> write_report(const std::string& dir, const RigCalResult& result,
                            const RigCalOptions& options);

}  // namespace mocap::rigcal
