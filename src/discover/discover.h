// Design: `mocap discover` as a library: from the 3D points of a recording to
// targets.yaml, joints.yaml and the calibrated model (docs/discover.md). Steps:
// point_tracker.h (point noise, short-term tracks) -> rigid_groups.h (rigid clusters)
// -> body_builder.h (targets, poses) -> the tracker's poses of those targets (a
// PoseSource, src/track, as `mocap calibrate` tracks) -> topology.h (joint tree and
// types; body_union.h merges one body built as two, then tracks and joins again) ->
// src/kinematics calibrate_joints (Eq. 2 / rank-5 + Ceres refinement, exactly
// as `mocap calibrate`). Bad recordings (too few frames, nothing moving, no body or a
// single body) are one-line errors prefixed by the recording's name; doubts are
// warnings (unplaced tracks, symmetric targets, too little motion), never guesses.
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "core/expected.h"
#include "discover/discover_types.h"
#include "formats/joints_yaml.h"
#include "formats/targets_yaml.h"
#include "kinematics/calibrate.h"

namespace mocap::discover {

struct DiscoverStats {
  int frames = 0;
  long long points = 0;
  int tracks = 0;       // all short-term tracks
  int long_tracks = 0;  // seen in >= min_track_frames frames
  int clusters = 0;
  double point_noise_mm = 0.0;  // used (stated, or estimated from the tracks)
  int unplaced_tracks = 0;
  int merged_bodies = 0;  // bodies built as two, merged at their shared joint (body_union.h)
  // The derived frame counts of the rigidity tests (discover_types.h) for the noise used.
  int min_covisible_frames = 0, min_placement_frames = 0;
  double seconds_tracking = 0.0, seconds_grouping = 0.0, seconds_bodies = 0.0,
         seconds_tracker = 0.0, seconds_topology = 0.0, seconds_calibration = 0.0;
};

struct DiscoverResult {
  TargetSet targets;    // body0..N-1: joined trees first (root, then breadth-first)
  JointModel topology;  // joints.yaml (names "<parent>_<child>")
  JointModel model;     // model.yaml (calibrated; empty when there is no joint)
  kinematics::CalibrationResult calibration;
  kinematics::CalibrationInput input;  // poses and markers per frame (targets' body order)
  std::vector<std::string> warnings;   // one line each
  DiscoverStats stats;
};

// Poses of given targets in every frame of the recording (frame i of PointSequence).
using PoseSource = std::function<Expected<kinematics::CalibrationInput>(const TargetSet& targets)>;

// The tracker as the pose source (`mocap calibrate`'s front half, src/track
// calibration_input.h): identification on every stereo point of a frame, partial markers
// left out of the fits. `progress` (frames done, total) may be empty.
PoseSource tracker_poses(const std::string& recording,
                         std::function<void(std::int64_t, std::int64_t)> progress = {});

// `label` (the recording folder) prefixes error messages. With a `poses` source, the
// bodies found (steps 1-4) are tracked again with their discovered targets and the
// joint topology and calibration (steps 5-6) use those poses: the tracker poses a body
// in every frame where its target can be identified, not only where 3 of the long
// tracks are seen. Without one (or when it fails: a warning), the discovery poses.
Expected<DiscoverResult> discover_model(const PointSequence& points, const DiscoverOptions& options,
                                        const std::string& label, const PoseSource& poses = {});

}  // namespace mocap::discover
