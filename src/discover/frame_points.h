// Design: step 1a of `mocap discover`: every frame of a recording through the tracker's
// own detection (src/detect, one detector per camera of the stereo pair) and stereo
// correspondence + optimal triangulation (src/stereo), without identification (there
// are no targets yet). Only points that can be trusted as one whole marker are kept:
// candidates that share a blob with another (epipolar ambiguity) and points from
// blobs flagged merged, split, truncated or touching the border are left out (counted),
// so that the rigidity tests see unbiased points.
#pragma once

#include <cstdint>
#include <functional>
#include <string>

#include "core/expected.h"
#include "discover/discover_types.h"

namespace mocap::discover {

struct PointsProgress {
  std::function<void(std::int64_t done, std::int64_t total)> progress;
  std::function<void(const std::string& message)> warn;
};

// Errors name the recording's file (rig.yaml, frames.csv, a PGM) and the problem.
Expected<PointSequence> triangulate_recording(const std::string& recording_dir,
                                              const PointsProgress& callbacks = {});

}  // namespace mocap::discover
