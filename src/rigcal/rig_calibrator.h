// Design: the wand calibration of a rig of 2..32 cameras (kMinRigCameras..kMaxRigCameras),
// end to end (`mocap calibrate-rig`):
//  1. detect blobs in every frame of the wand recording (BlobDetector; merged, split
//     and border blobs are dropped, and less round ones unless they are wand balls
//     whose edge is fitted), the centres and their covariances from the balls' edges
//     (detect_recording), and label the wand per image (wand_labeler.h); a frame takes
//     part when the wand is labelled in at least two cameras;
//  2.-3. initial rig, pairwise from camera 0 (pairwise_init.h): per camera a RANSAC
//     essential matrix with camera 0 (or, with too few shared frames, with the
//     best-connected initialised camera), metric scale from the wand length, the inner
//     markers' spacing checked against wand.yaml;
//  4. one joint bundle adjustment (bundle.h, each centre weighed by its covariance) of
//     every camera's pose but camera 0's and every wand pose, then, for each camera that the wand
//     covered well in enough frames (or when asked), of its intrinsics and distortion too;
//  5. quality: per camera reprojection RMS, frames, coverage, label statuses and pose
//     relative to camera 0; wand-length error of independently triangulated ends
//     (mean, RMS); warnings for too little coverage or too few frames;
//  6. optionally the ground frame from an L-frame recording (ground_frame.h).
// The result's world is camera 0's frame, or the L-frame's when one was given.
// Setup-time code: allocates, returns one-line errors.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "camera/camera_model.h"
#include "core/camera_set.h"
#include "core/expected.h"
#include "detect/detector_config.h"
#include "formats/wand_yaml.h"
#include "rigcal/bundle.h"
#include "rigcal/ground_frame.h"
#include "rigcal/wand_centres.h"
#include "rigcal/wand_labeler.h"

namespace mocap::rigcal {

inline constexpr std::size_t kMinRigCameras = 2;
inline constexpr std::size_t kMaxRigCameras = kMaxCameras;  // the rig's bound

enum class IntrinsicsMode { kAuto, kRefine, kFixed };

struct RigCalOptions {
  detect::DetectorConfig detector{};
  double min_roundness = 0.95;  // of the expected roundness (detect_recording)
  bool edge_centres = true;     // balls' centres from their edges (detect_recording)
  double rod_cut_deg = 0.0;     // the wand rim left out on the rod's side: 0 = chosen from
                                // the recording (wand_centres.h), > 0 = this (20..60)
  bool weight_centres = true;   // the bundle weighs each centre by its covariance
  WandLabelConfig label{};
  IntrinsicsMode intrinsics = IntrinsicsMode::kAuto;
  int min_frames = 30;            // fewer frames with the wand in >= 2 cameras: error; also the
                                  // fewest frames a camera shares with its initialisation partner
  int warn_frames = 200;          // fewer: warning
  double warn_coverage = 0.5;     // occupied fraction of the coverage grid below: warning
  double refine_coverage = 0.75;  // kAuto refines a camera's intrinsics only above this
  int refine_min_frames = 200;    // ... and with at least this many used frames in it
  int coverage_cols = 16;
  int coverage_rows = 12;
  double max_spacing_error = 0.02;  // measured inner-marker fraction vs wand.yaml
  std::uint64_t seed = 1;           // RANSAC
  GroundFrameOptions ground{};
};

struct CameraQuality {
  std::string name;
  int frames_labelled = 0;
  std::array<int, 5> label_status{};  // count per LabelStatus
  double reprojection_rms_px = 0.0;
  double coverage = 0.0;             // occupied fraction of the grid
  std::vector<Vec2> wand_points_px;  // every labelled wand marker (for the coverage image)
  int frames_used = 0;               // bundle frames with the wand labelled in this camera
  bool intrinsics_refined = false;
  std::string initialised_from;        // the reference camera of its initial pose ("" for cam 0)
  int essential_inliers = 0;           // of that pair's RANSAC
  Iso3 T_cam_cam0 = Iso3::Identity();  // pose relative to camera 0: X_cam = T X_cam0
  double baseline_mm = 0.0;            // distance of its centre from camera 0's
};

struct RigCalResult {
  std::vector<CameraModel> cameras;  // world = camera 0 or the L-frame
  std::vector<CameraQuality> quality;
  int frames_total = 0;
  int frames_both = 0;        // wand labelled in at least two cameras (both, for a pair)
  int frames_used = 0;        // after the bundle adjustment's outlier rejection
  int essential_inliers = 0;  // summed over the initialisation pairs
  double baseline_mm = 0.0;   // camera 1's distance from camera 0
  double wand_length_mean_error_mm = 0.0;
  double wand_length_rms_error_mm = 0.0;
  int wand_length_samples = 0;
  bool intrinsics_refined = false;
  std::string intrinsics_note;
  BundleStats bundle;
  bool has_ground = false;
  GroundFrameResult ground;
  std::vector<std::string> warnings;
  // How the wand balls' centres were found (set by the caller from detect_recording;
  // written to the report when end_ball_views > 0).
  RodCutChoice wand_centres;                // whole end balls (detect_recording)
  RodCutChoice wand_centres_partly_hidden;  // partly hidden end balls
};

// A rig calibration needs kMinRigCameras..kMaxRigCameras cameras; else the one-line
// error "<recording>/rig.yaml: cameras: ...".
Expected<void> check_camera_count(std::size_t cameras, const std::string& recording);

// The blobs of a recording (detect_recording) and, for a wand, how its balls' centres
// were found.
struct DetectedRecording {
  FrameBlobs blobs;
  FrameCentreInfo info;  // per centre: the edge fit's covariance, partly hidden or not
  RodCutChoice rod_cut;  // whole end balls; end_ball_views = 0 without a wand or edge centres
  RodCutChoice rod_cut_partly_hidden;  // the partly hidden end balls
  std::vector<std::string> notes;      // one line each (blob recordings: see below)
};

// A blob recording (formats/recording.h) is read, not detected: its blob lists as the
// recorder's detector found them (its settings, not options.detector), without edge fits
// (they need the images): the centres are the centroids, partly hidden balls are left
// out, and a note says so.
// Detects blobs in every frame of a recording (every camera of its rig.yaml: 2..32, else
// a one-line error naming the rig.yaml). Blobs that are merged, split or touch the
// border are left out. A blob less round than options.min_roundness x the roundness a
// whole ball has at that place in the image (a ball's image is an ellipse stretched
// radially by perspective and squeezed by barrel distortion, expected_roundness()) is
// partly hidden and its centroid biased: it is kept only as a labelled wand ball whose
// edge is fitted (with options.edge_centres and a wand; else it is left out). cams: the
// intrinsics for that expectation (the recording's rig.yaml when null).
// options.edge_centres: each kept blob's centre is its silhouette edge's
// (detect/edge_centre.h, with the shape a whole ball has there), moved to the
// projection of the ball's centre (ball_centre_pixel), with the fit's covariance; the
// centroid stays where the edge fit fails. wand (with options.label): the wand is
// labelled on the centroids of each image (all kept blobs, else the round ones) and its
// balls' centres come from WandCentres (wand_centres.h: the rim along the axis left out
// on the rod's side, the cut chosen from the recording unless options.rod_cut_deg fixes
// it); null: no axis (an L-frame).
Expected<DetectedRecording> detect_recording(const std::string& dir, const RigCalOptions& options,
                                             const std::vector<CameraModel>* cams = nullptr,
                                             const WandSpec* wand = nullptr);

// Minor/major axis ratio of a small ball's image centred at pixel px (first order:
// perspective stretch 1/cos(off-axis angle) and the distortion's radial/tangential
// scales).
double expected_roundness(const CameraModel& cam, const Vec2& px) noexcept;
// The same shape as the ratio of its radial extent (along the line from the principal
// point) to its tangential extent: > 1 stretched radially, < 1 squeezed (1 on failure).
double expected_radial_stretch(const CameraModel& cam, const Vec2& px) noexcept;

// The calibration from already detected blobs. intrinsics: the cameras' intrinsics
// (2..32; names and sizes must be set; extrinsics ignored), blobs with one entry per
// camera. info (optional, the shape of blobs): the centres' covariances, which weigh the
// bundle adjustment's residuals (BundleOptions::weight_by_covariance), and which are
// partly hidden (left out of the wand-length figure). source names the
// recording in errors (a wrong camera count names source/rig.yaml).
Expected<RigCalResult> calibrate_from_blobs(const FrameBlobs& blobs, const WandSpec& wand,
                                            const std::vector<CameraModel>& intrinsics,
                                            const RigCalOptions& options, const std::string& source,
                                            const FrameCentreInfo* info = nullptr);

// Sets the ground frame of a calibrated result from an L-frame recording's blobs.
Expected<void> set_ground_frame(RigCalResult& result, const FrameBlobs& lframe_blobs,
                                const LFrameSpec& lframe, const RigCalOptions& options,
                                const std::string& source);

}  // namespace mocap::rigcal
