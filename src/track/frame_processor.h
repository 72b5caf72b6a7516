// Design: the per-frame stages of the tracker in one object, shared by the offline
// `mocap track` and the live pipeline: detect (one detector per camera) -> correspondence
// + optimal triangulation -> rigid-target identification -> joint angles.
// Cameras: the rig's 2..kMaxCameras cameras all take part. Two cameras: one stereo pair
// (stereo_triangulator.h), exactly as the paper. More: one triangulator per camera pair
// proposes candidates and the MultiViewMerger (multiview.h) merges them into N-view
// points refined over every camera that sees them, pair by pair (a pair does not
// triangulate two blobs earlier pairs settled: multiview.h, "Settled blobs"); a view whose blob
// does not look like a whole marker (marker_shape.h) is then left out of the point when two or more
// whole views remain, so an occluded view no longer biases a point other cameras see clearly. A
// camera whose frame is missing takes no part in that frame: with two cameras the frame yields no
// 3D points (spec); with more, the others still triangulate (at least two present). Immutable
// configuration plus preallocated workspace: create() validates and allocates every buffer from the
// stated bounds; the per-frame calls are noexcept, allocate nothing and never throw. The live
// pipeline calls the stages separately (detect_camera() on the detect threads, then
// process_blobs()); `process()` runs them in sequence and times them.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <span>
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
#include "kinematics/joint_rates.h"
#include "stereo/multiview.h"
#include "stereo/stereo_triangulator.h"
#include "stereo/undistorted_blobs.h"
#include "track/body_motion.h"
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
  // Rigs with more than two cameras: the N-view merge (its capacities follow `stereo`).
  MultiViewConfig multiview{};
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
  // The causal joint rates of every frame with a model (kinematics/joint_rates.h) and the
  // body velocities of every frame (track/body_motion.h).
  kinematics::RateFilterConfig velocity{};
};

// Wall-clock duration of each stage of one frame (ns). `detect` covers every camera.
struct StageTimesNs {
  std::int64_t load = 0;  // reading the frame from a recording (offline only; not in frame)
  std::int64_t detect = 0;
  std::int64_t triangulate = 0;
  std::int64_t identify = 0;
  std::int64_t angles = 0;
  std::int64_t frame = 0;
};

// Everything one frame produces; sized by FrameProcessor::make_output() at setup.
struct FrameOutput {
  std::vector<detect::BlobList> blobs;             // one per camera of the rig
  std::array<bool, kMaxCameras> camera_present{};  // false: the camera's frame was missing
  // Per camera (3+ cameras): its blobs undistorted where they were detected
  // (FrameProcessor::undistort_camera), which stage 2 then takes instead of undistorting
  // them itself; received < 0: none. Stage 2 marks them consumed.
  std::vector<UndistortedStore> undistorted;
  PointList points;
  BodyPoses poses;
  kinematics::JointAngles angles;
  std::vector<kinematics::BodyRate> body_rates;  // one per target
  StageTimesNs times;
};

class FrameProcessor {
 public:
  // `model` may be null (no joint angles). Every camera of the rig (2..kMaxCameras) is used.
  static Expected<FrameProcessor> create(const Rig& rig, const TargetSet& targets,
                                         const JointModel* model, const TrackerConfig& config);

  FrameOutput make_output() const;

  // All stages of one frame; views[c] is camera c's image (views beyond views.size()
  // count as missing). A null view means that camera's frame is missing (see the top).
  bool process(std::span<const ImageView* const> views, std::int64_t timestamp_ns,
               FrameOutput& out) noexcept;

  // Stage 1 alone, for one camera (thread-safe between different cameras).
  bool detect_camera(int camera, const ImageView& image, detect::BlobList& out) noexcept;
  // Stages 2-4 on the blobs already in `out.blobs` (camera_present must be set).
  bool process_blobs(std::int64_t timestamp_ns, FrameOutput& out) noexcept;
  // Stage 2's first step for one camera, where its blobs were detected (thread-safe
  // between different cameras): their undistortion into `out` (FrameOutput::undistorted
  // of that camera, or a store handed on with the blobs), bit for bit what stage 2 would
  // compute; it moves that work off the thread of stages 2-4. 2 cameras: nothing (none).
  void undistort_camera(int camera, const detect::BlobList& blobs,
                        UndistortedStore& out) const noexcept;

  // Forget temporal state (identification priors, hinge unwrapping, joint and body rates).
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
  int camera_count() const noexcept { return static_cast<int>(detectors_.size()); }
  // The pairwise stereo counters summed over the camera pairs (one pair: its own;
  // points_in[0] and [1] then sum each pair's first and second camera).
  const StereoCounters& stereo_counters() const noexcept { return stereo_total_; }
  // The merger's counters and undistorted_late (the camera frames triangulate() undistorted
  // itself), as of the last frame.
  const MultiViewCounters& multiview_counters() const noexcept { return multiview_total_; }
  const IdentifyCounters& identify_counters() const noexcept { return identifier_.counters(); }
  // Joint-rate filter counters; null without a model.
  const kinematics::RateFilterCounters* rate_counters() const noexcept {
    return rates_ ? &rates_->counters() : nullptr;
  }
  // Body-velocity filter counters.
  const kinematics::RateFilterCounters& body_rate_counters() const noexcept {
    return body_motion_->counters();
  }
  // Chain-tracking counters; null without a model.
  const ChainCounters* chain_counters() const noexcept {
    return chain_ ? &chain_->counters() : nullptr;
  }
  // Setup warnings, one line each: the identifier's (ambiguous targets) and the chain
  // model's (joints left out of chain tracking).
  const std::vector<std::string>& warnings() const noexcept { return warnings_; }

 private:
  FrameProcessor(Rig rig, TargetSet targets, JointModel model,
                 std::vector<detect::BlobDetector> detectors, std::vector<StereoTriangulator> pairs,
                 MultiViewMerger merger, Identifier identifier,
                 std::optional<kinematics::JointAngleSolver> angles);
  // Stereo and N-view merge into out.points from out.blobs and out.camera_present.
  void triangulate(FrameOutput& out) noexcept;
  void triangulate_points(FrameOutput& out) noexcept;
  // Marks the identification's input; drops unfit views of points seen by 3+ cameras.
  void measure_points(FrameOutput& out) noexcept;
  // Chain tracking after identification: chain-solved bodies join out.poses.
  void track_chain(int n_points, std::int64_t timestamp_ns, FrameOutput& out) noexcept;
  // False when the blob of a marker at X_world does not look like a whole marker.
  bool whole_marker_view(int camera, const detect::BlobList& blobs, int blob,
                         const Vec3& X_world) const noexcept;

  Rig rig_;
  std::vector<MarkerShapeModel> shapes_;  // one per camera
  TargetSet targets_;
  JointModel model_;
  std::vector<detect::BlobDetector> detectors_;  // one per camera
  std::vector<StereoTriangulator> pairs_;        // one per camera pair (a < b)
  MultiViewMerger merger_;
  StereoCounters stereo_total_;
  MultiViewCounters multiview_total_;
  std::uint64_t undistorted_late_ = 0;
  Identifier identifier_;
  std::optional<kinematics::JointAngleSolver> angles_;
  std::optional<ChainSolver> chain_;
  std::optional<kinematics::JointRateFilter> rates_;
  std::optional<BodyMotion> body_motion_;  // set by create()
  ChainResult chain_result_;
  std::vector<std::string> warnings_;
  // Workspace, sized at create().
  std::vector<std::vector<Vec2>> centroids_px_;  // per camera
  std::vector<PointList> pair_points_;           // per camera pair (3+ cameras)
  std::vector<BlobUndistorter> undistorters_;    // per camera (3+ cameras): once per frame
  std::vector<MeasuredPoint> measured_;
  std::vector<double> partial_sigma_mm_;    // per measured point: its noise when partial
  double marker_radius_mm_ = 0.0;           // targets.yaml marker_diameter / 2 (0: unknown)
  double fallback_partial_sigma_mm_ = 1.0;  // without a marker size: IdentifyConfig's
  int measured_count_ = 0;
  PointSelector selector_;
  std::vector<kinematics::BodyPoseView> body_views_;
};

}  // namespace mocap
