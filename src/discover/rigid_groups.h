// Design: step 2a of `mocap discover`: grouping point tracks into rigid bodies by the
// constancy of their pairwise distances. For each pair of tracks, over the frames where
// both are seen (at most max_pair_frames, evenly subsampled):
//  - non-rigid: the robust std of the distance (1.4826 * MAD) exceeds 2 b, or more than
//    20 % of the frames deviate from the median by more than 4 b (b =
//    pair_distance_std_mm(), 3 sqrt(2) point sigmas), with at least 5 common frames;
//  - rigid: at least min_covisible_frames() common frames, robust std <= b, at most 5 %
//    deviating frames, AND the test meant something: the pair's direction turned by at
//    least min_pair_turn_rad(its length) (10 b / length: enough for a non-rigid pair to
//    fail the 20 % rule), or both points stayed put (static_tolerance_mm) while the scene
//    moved in at least half of the common frames, and in at least min_covisible_frames()
//    (a still torso); both derived from the noise (discover_types.h);
//  - unknown otherwise (too few frames, too little motion, in between).
// Clusters grow by agglomeration over the rigid pairs (most common frames first):
// clusters X and Y merge only when no pair between them is non-rigid and at least
// min(3, |X| |Y|) pairs between them are rigid, repeated until nothing merges. A track
// that cannot be placed stays out (never guessed); body_builder.h re-links fragments.
#pragma once

#include <vector>

#include "discover/discover_types.h"

namespace mocap::discover {

enum class PairRelation : unsigned char { kUnknown, kRigid, kNonRigid };

// Per frame: 1 when some track of at least min_track_frames moved faster than
// min_scene_speed_mm_per_s between the previous frame and this one.
std::vector<char> scene_motion(const PointSequence& seq, const std::vector<PointTrack>& tracks,
                               const DiscoverOptions& options);

PairRelation classify_pair(const PointTrack& a, const PointTrack& b,
                           const std::vector<char>& moving, const DiscoverOptions& options);

// Clusters of indices into `tracks` (only tracks with seen >= min_track_frames take part),
// largest first; clusters of fewer than 3 tracks are not returned.
std::vector<std::vector<int>> group_rigid_tracks(const std::vector<PointTrack>& tracks,
                                                 const std::vector<char>& moving,
                                                 const DiscoverOptions& options);

}  // namespace mocap::discover
