// Design: step 1b of `mocap discover`: short-term tracking of unlabelled 3D points.
// Each track predicts its next position with a constant velocity (from its last two
// measurements) and is extended by the point in its gate when the link is unambiguous:
// the point is the track's nearest, the track is the point's nearest, and the runner-up
// on both sides is clearly farther (more than twice the distance and more than two
// noise gates). An ambiguous track ends; its point starts a new track, and the grouping
// step re-links the fragments. Gates (mm), with sigma = point_noise_mm and dt the time
// since the track's last measurement:
//   with a velocity:    g = gate_sigmas * 3 sigma + max_accel * dt^2
//   without (new track): g = gate_sigmas * 2 sigma + max_speed * dt, and the velocity
// the link implies must predict a point of the next frame within the first gate
// so they scale with the frame interval. A track coasts over at most max_gap_frames
// frames without a point (NaN entries), then ends.
#pragma once

#include <vector>

#include "discover/discover_types.h"

namespace mocap::discover {

std::vector<PointTrack> track_points(const PointSequence& points, const DiscoverOptions& options);

}  // namespace mocap::discover
