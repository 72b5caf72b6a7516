// Design: the per-frame stages of the tracker in one object, shared by the offline
// `mocap track` and the live pipeline: detect (one detector per camera) -> stereo
// correspondence + optimal triangulation -> rigid-target identification -> joint angles.
// Immutable configuration plus preallocated workspace: create() validates and allocates
// every buffer from the stated bounds; the per-frame calls are noexcept, allocate
// nothing and never throw. The live pipeline calls the stages separately (detect_camera()
// on two threads, then process_blobs()); `process()` runs them in sequence and times them.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "camera/camera_model.h"
#include "core/expected.h"
#include "core/image.h"
#include "detect/blob_detector.h"
#include "formats/joints_yaml.h"
#include "formats/targets_yaml.h"
#include "identify/identifier.h"
#include "kinematics/joint_angles.h"
#include "stereo/stereo_triangulator.h"
#include "track/chain_solver.h"
#include "track/marker_shape.h"
#include "track/point_selection.h"

namespace mocap {

struct TrackerConfig {
  detect::DetectorConfig detect{[] {
    detect::DetectorConfig c;
    c.max_elongation = 1.3;
    return c;
  }()};
  StereoConfig stereo{};
  IdentifyConfig identify{[] {
    IdentifyConfig c;
    c.max_speed_mm_per_s = 3000.0;
    c.max_angular_speed_deg_per_s = 1440.0;
    return c;
  }()};
  // A marker's image is taken as whole when its blob is not flagged (border, merged,
  // split, truncated) and its shape agrees, in both cameras, with the silhouette the
  // full camera model predicts for a ball of the targets' marker_diameter at its 3D
  // point (track/marker_shape.h). Otherwise its 3D point is `partial`
  // (identify_types.h). `marker_shape.enabled = false`: the flags alone decide.
  MarkerShapeConfig marker_shape{};
  // Which 3D candidates are reported (Point3::reported; track/point_selection.h).
  PointSelectionConfig selection{};
  // Kinematic-chain tracking, used whenever a model is loaded. Its point noise, partial
  // noise, confidence and angular speed bound are taken from `identify` at create() (one
  // source for each); the other keys are its own.
  ChainConfig chain{};
};

// Wall-clock duration of each stage of one frame (ns). `detect` covers both cameras.
struct StageTimesNs {
  std::int64_t detect = 0;
  std::int64_t triangulate = 0;
  std::int64_t identify = 0;
  std::int64_t angles = 0;
  std::int64_t frame = 0;
};

// Everything one frame produces; sized by FrameProcessor::make_output() at setup.
struct FrameOutput {
  std::array<detect::BlobList, 2> blobs;
  std::array<bool, 2> camera_present{};  // false: the camera's frame was missing
  PointList points;
  BodyPoses poses;
  kinematics::JointAngles angles;
  StageTimesNs times;
};

class FrameProcessor {
 public:
  // `model` may be null (no joint angles). The rig's first two cameras are the stereo pair.
  static Expected<FrameProcessor> create(const Rig& rig, const TargetSet& targets,
                                         const JointModel* model, const TrackerConfig& config);

  FrameOutput make_output() const;

  // All stages of one frame. A null view means that camera's frame is missing: the
  // frame then yields no 3D points (spec), and identification sees an empty frame.
  bool process(const ImageView* cam0, const ImageView* cam1, std::int64_t timestamp_ns,
               FrameOutput& out) noexcept;

  // Stage 1 alone, for camera 0 or 1 (thread-safe between the two cameras).
  bool detect_camera(int camera, const ImageView& image, detect::BlobList& out) noexcept;
  // Stages 2-4 on the blobs already in `out.blobs` (camera_present must be set).
  bool process_blobs(std::int64_t timestamp_ns, FrameOutput& out) noexcept;

  // Forget temporal state (identification priors, hinge unwrapping).
  void reset() noexcept;

  // Whether 3D point i of the last processed frame was measured from a partial marker
  // image (see TrackerConfig); false for an index outside that frame.
  bool point_partial(int i) const noexcept {
    return i >= 0 && i < measured_count_ && measured_[static_cast<std::size_t>(i)].partial;
  }

  bool has_model() const noexcept { return angles_.has_value(); }
  const TargetSet& targets() const noexcept { return targets_; }
  const JointModel& model() const noexcept { return model_; }
  const Rig& rig() const noexcept { return rig_; }
  const detect::DetectorCounters& detector_counters(int camera) const noexcept {
    return detectors_[static_cast<std::size_t>(camera)].counters();
  }
  const StereoCounters& stereo_counters() const noexcept { return stereo_.counters(); }
  const IdentifyCounters& identify_counters() const noexcept { return identifier_.counters(); }
  // Chain-tracking counters; null without a model.
  const ChainCounters* chain_counters() const noexcept {
    return chain_ ? &chain_->counters() : nullptr;
  }
  // Setup warnings, one line each: the identifier's (ambiguous targets) and the chain
  // model's (joints left out of chain tracking).
  const std::vector<std::string>& warnings() const noexcept { return warnings_; }

 private:
  FrameProcessor(Rig rig, TargetSet targets, JointModel model,
                 std::array<detect::BlobDetector, 2> detectors, StereoTriangulator stereo,
                 Identifier identifier, std::optional<kinematics::JointAngleSolver> angles);
  // Chain tracking after identification: chain-solved bodies join out.poses.
  void track_chain(int n_points, std::int64_t timestamp_ns, FrameOutput& out) noexcept;
  // False when the blob of a marker at X_world does not look like a whole marker.
  bool whole_marker_view(int camera, const detect::BlobList& blobs, int blob,
                         const Vec3& X_world) const noexcept;

  Rig rig_;
  std::vector<MarkerShapeModel> shapes_;  // one per stereo camera
  TargetSet targets_;
  JointModel model_;
  std::array<detect::BlobDetector, 2> detectors_;
  StereoTriangulator stereo_;
  Identifier identifier_;
  std::optional<kinematics::JointAngleSolver> angles_;
  std::optional<ChainSolver> chain_;
  ChainResult chain_result_;
  std::vector<std::string> warnings_;
  // Workspace, sized at create().
  std::array<std::vector<Vec2>, 2> centroids_px_;
  std::vector<MeasuredPoint> measured_;
  int measured_count_ = 0;
  PointSelector selector_;
  std::vector<kinematics::BodyPoseView> body_views_;
};

}  // namespace mocap
