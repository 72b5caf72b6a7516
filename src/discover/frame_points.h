// Design: step 1a of `mocap discover`: every frame of a recording through the tracker's
// own stages (track/frame_processor.h, default TrackerConfig) over every camera of the
// rig (2..kMaxCameras): detection, pairwise correspondence + optimal triangulation and,
// for three or more cameras, the N-view merge; without targets (there are none yet), so
// nothing is identified. A frame in which a camera is missing still gives the points of
// the others when two or more remain (a stereo pair: none). Only points that can be trusted as one
// whole marker are kept: candidates that share a blob with another (epipolar ambiguity) and points
// the tracker marks partial (a view not a whole marker: flagged merged, split, truncated or at the
// border, or misshapen, track/marker_shape.h, with fewer than two whole views left; with two or
// more the tracker refits the point from them) are left out (counted), so that the rigidity tests
// see unbiased points.
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
