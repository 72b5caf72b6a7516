// Design: step 2b + 3 of `mocap discover`: from the rigid clusters of rigid_groups.h to
// marker targets and per-frame body poses.
//  1. Seed: the cluster's reference frame is the frame in which most of its tracks are
//     seen (at least 3); those tracks are the first markers, in a temporary frame with
//     the world's axes there.
//  2. Poses: per frame, Umeyama fit of the markers seen (>= 3); the worst marker is
//     dropped while its residual exceeds 5 fit tolerances (a re-used or stray point).
//  3. Placement of a track (the cluster's other tracks, then every long track left
//     over, the fragments of occluded markers included): its positions mapped into the
//     body frame must agree (RMS <= body_fit_tolerance_mm, <= 5 % beyond 4x) over at
//     least min_placement_frames() posed frames, and the agreement must mean something
//     (the body turned by min_body_turn_rad(lever) over those frames, or stayed still with
//     the point while the scene moved). The point then joins the marker within
//     marker_diameter/4 that it never coexists with (a re-linked fragment), or becomes
//     a new marker when farther than one marker diameter from all; anything in between,
//     or a track that fits two bodies, is left out and reported.
//  4. Duplicates of one body (built from clusters of different time windows, or from
//     fragments of a still body) are merged (body_merge.cpp), then every long track left
//     over is placed in the one body it fits; merge and placement run a second time
//     when the first merged anything.
//  5. Refinement: poses and marker positions (per-axis median of T_world_body^-1 X over
//     all the marker's frames) alternately, twice.
//  6. Body frame (docs/discover.md): origin at the markers' centroid, axes parallel to
//     the world axes at the reference frame.
#pragma once

#include <vector>

#include "discover/discover_types.h"
#include "kinematics/calibrate.h"

namespace mocap::discover {

struct DiscoveredBody {
  std::vector<Vec3> markers_body;               // mm, body frame
  std::vector<std::vector<int>> marker_tracks;  // per marker: indices into the tracks
  std::vector<char> found;                      // per frame
  std::vector<Iso3> T_world_body;               // per frame (valid where found)
  int reference_frame = 0;
  double motion_rms_mm = 0.0;  // RMS displacement of the origin about its mean (root choice)
};

struct BodyBuild {
  std::vector<DiscoveredBody> bodies;
  std::vector<int> unplaced_tracks;  // long tracks (>= min_track_frames) in no body
};

BodyBuild build_bodies(const std::vector<PointTrack>& tracks,
                       const std::vector<std::vector<int>>& groups, const std::vector<char>& moving,
                       const DiscoverOptions& options);

// The tracker-style calibration input (per frame, per body: pose and matched markers).
kinematics::CalibrationInput make_calibration_input(const std::vector<DiscoveredBody>& bodies,
                                                    const std::vector<PointTrack>& tracks,
                                                    std::size_t frame_count,
                                                    const DiscoverOptions& options);

}  // namespace mocap::discover
