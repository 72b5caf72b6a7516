// Design: reader/writer of the spec's rig.yaml (camera intrinsics, OpenCV distortion,
// world->camera extrinsics). Validation is complete at load: every problem is one
// line "<file>: <key>: <problem>" (missing key, wrong type, wrong size, NaN/Inf,
// R not a rotation, non-positive size or focal length, duplicate camera names).
#pragma once

#include <string>

#include "camera/camera_model.h"
#include "core/expected.h"

namespace mocap {

Expected<Rig> load_rig(const std::string& path);
Expected<void> save_rig(const std::string& path, const Rig& rig);

}  // namespace mocap
