// Design: accuracy of the tracker's outputs against the simulator's ground truth
// (gt/poses.csv, gt/angles.csv, gt/markers.csv; see docs/simulator.md). Used by
// `mocap track --truth`, the end-to-end tests and the evaluation script. Offline only.
#pragma once

#include <algorithm>
#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "core/camera_set.h"
#include "core/expected.h"
#include "core/types.h"
#include "formats/csv_outputs.h"
#include "formats/joints_yaml.h"
#include "formats/targets_yaml.h"

namespace mocap {

struct GtMarker {
  std::int64_t frame = 0;
  std::string body;
  int marker = 0;
  Vec3 X_world = Vec3::Zero();
  int cameras = 0;                          // cameras of the recording (columns uK,vK,visK)
  std::array<Vec2, kMaxCameras> px{};       // per camera, the first `cameras` entries
  std::array<bool, kMaxCameras> visible{};  // visible, unmerged, inside the image
  // Cameras that see the marker cleanly; a 3D point is expected from two or more.
  int views() const noexcept {
    return static_cast<int>(std::count(visible.begin(), visible.end(), true));
  }
};

// A joint of the true model, for observability (evaluate_against_truth).
struct GtJoint {
  std::string name;
  std::string parent;
  std::string child;
  bool hinge = false;
};

struct GroundTruth {
  std::vector<PoseRow> poses;
  std::vector<AngleRow> angles;
  std::vector<GtMarker> markers;  // sorted by frame
  std::vector<GtJoint> joints;    // from model_true.yaml, when present
};

// Reads DIR/poses.csv, DIR/angles.csv (optional) and DIR/markers.csv. When DIR holds
// model_true.yaml (and DIR/../targets.yaml exists), the true joint angles are recomputed
// from the true poses in the tracker's angle convention (true_angles_from_poses).
Expected<GroundTruth> load_ground_truth(const std::string& gt_dir);
// Joint angles of `model` for each frame of `poses` (rows sorted by frame), as the
// tracker computes them (kinematics::JointAngleSolver).
Expected<std::vector<AngleRow>> true_angles_from_poses(const TargetSet& targets,
                                                       const JointModel& model,
                                                       const std::vector<PoseRow>& poses);
Expected<std::vector<GtMarker>> read_gt_markers_csv(const std::string& path);

struct BodyAccuracy {
  std::string body;
  std::int64_t frames_visible = 0;  // frames with >= 3 of its markers visible in >= 2 cameras
  std::int64_t frames_found = 0;    // of those, frames where the tracker found the body
  std::int64_t frames_found_total = 0;
  std::int64_t wrong = 0;        // found with a pose far from the truth (> 10 mm or > 5 deg)
  double position_rms_mm = 0.0;  // over correct finds
  double rotation_rms_deg = 0.0;
};

// Observability of a joint in a frame (the issue's definition, docs/chain.md "Coverage
// statistics"): a marker is clean when it is visible (vis = 1) in 2 or more cameras; a
// body is observed when it has >= 3 clean markers, or when the joint into it is
// observable; a joint is observable when its parent is observed and its child has >= 1
// (hinge) or >= 2 (ball) clean markers. Needs GroundTruth::joints.
struct JointAccuracy {
  std::string joint;
  std::int64_t frames = 0;  // frames with a valid angle
  double rms_deg = 0.0;     // ball: geodesic angle of the relative rotation; hinge: angle
  double max_deg = 0.0;
  std::int64_t over_2deg = 0;         // valid frames more than 2 deg off
  std::int64_t observable = 0;        // frames in which the joint is observable (above)
  std::int64_t valid_observable = 0;  // of those, frames with a valid angle
};

struct AccuracyReport {
  std::int64_t frames = 0;
  std::int64_t marker_views = 0;      // markers visible in >= 2 cameras, summed over frames
  std::int64_t markers_recalled = 0;  // of those, with a 3D point within 2 mm
  double point_rmse_mm = 0.0;         // over recalled markers
  std::int64_t points = 0;            // all 3D points written
  std::int64_t points_far = 0;        // points farther than 5 mm from every true marker
  std::vector<BodyAccuracy> bodies;
  std::vector<JointAccuracy> joints;
};

AccuracyReport evaluate_against_truth(const GroundTruth& truth, const std::vector<PointRow>& points,
                                      const std::vector<PoseRow>& poses,
                                      const std::vector<AngleRow>& angles);

// Human-readable multi-line summary.
std::string format_accuracy(const AccuracyReport& report);

}  // namespace mocap
