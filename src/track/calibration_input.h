// Design: the front half of `mocap calibrate`: runs a recording through the same
// FrameProcessor stages as `mocap track` (without joint angles) and collects, per frame
// and body, the identified pose and the matched marker positions that the kinematic
// calibration (src/kinematics) fits. Offline, setup-style code: it may allocate.
#pragma once

#include <cstdint>
#include <functional>
#include <string>

#include "core/expected.h"
#include "kinematics/calibrate.h"
#include "track/frame_processor.h"

namespace mocap {

struct CalibrationCollectOptions {
  TrackerConfig config{};
  std::function<void(std::int64_t done, std::int64_t total)> progress;
  std::function<void(const std::string& message)> warn;
};

struct CollectedCalibration {
  kinematics::CalibrationInput input;
  std::int64_t frames = 0;
  std::int64_t frames_all_bodies = 0;  // frames in which every body was found
};

Expected<CollectedCalibration> collect_calibration_input(const std::string& recording_dir,
                                                         const TargetSet& targets,
                                                         const CalibrationCollectOptions& options);

}  // namespace mocap
