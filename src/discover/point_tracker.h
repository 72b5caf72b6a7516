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

// Step 1b as discover runs it: with options.point_noise_mm = 0 (auto), a first pass with
// provisional_noise_mm gates and the noise estimated from its tracks
// (estimate_point_noise), then the pass with that noise; still markers' fragments
// stitched (stitch_still_fragments). Returns the tracks and the noise they were made
// with (options.point_noise_mm when it was given).
struct TrackedPoints {
  std::vector<PointTrack> tracks;
  double point_noise_mm = 0.0;
};
TrackedPoints point_tracks(const PointSequence& points, const DiscoverOptions& options);

// Re-links the fragments of a still marker: a marker that stands still (a still torso)
// but is hidden now and then (an arm passing in front) leaves one track per visible
// stretch. Tracks that stay within static_tolerance_mm of their median position over
// their whole life, never coexist, and whose medians agree within the noise gate
// (gate_sigmas * 3 sigma) are one marker and are joined (NaN over the gaps): two markers
// cannot stand at the same place in turn without the first one moving. Returns the
// tracks, joined ones merged into the earliest, sorted by first frame.
std::vector<PointTrack> stitch_still_fragments(std::vector<PointTrack> tracks,
                                               const DiscoverOptions& options);

// The per-axis noise of the recording's 3D points, estimated from its tracks: the third
// difference X(f+3) - 3 X(f+2) + 3 X(f+1) - X(f) of four consecutive measurements has
// noise variance 20 sigma^2 per axis, while smooth motion contributes only jerk * dt^3
// (10 m/s^3 at 100 fps: 0.01 mm). sigma = 1.4826 MAD / sqrt(20) per world axis over all
// samples, the largest of the three (stereo depth noise is 2-4x the lateral noise);
// motion can only inflate it (looser tolerances, never tighter). Returns `fallback`
// with fewer than 30 samples; never below 0.005 mm.
double estimate_point_noise(const std::vector<PointTrack>& tracks, double fallback);

}  // namespace mocap::discover
