// Design: the wand calibration of a stereo rig, end to end (`mocap calibrate-rig`):
//  1. detect blobs in every frame of the wand recording (BlobDetector; merged, split
//     and border blobs are dropped) and label the wand per image (wand_labeler.h);
//  2. initial relative pose: RANSAC essential matrix on the undistorted normalised wand
//     points of the frames labelled in both cameras (essential.h);
//  3. metric scale: the median triangulated end-to-end length against the wand's
//     length; the inner markers' measured positions are checked against wand.yaml
//     (a wrong spacing is an error, not a silently distorted rig);
//  4. bundle adjustment (bundle.h) of camera 1's pose and every wand pose, then, when
//     the wand covered both images well and enough frames were used (or when asked),
//     of the intrinsics and distortion too;
//  5. quality: reprojection RMS per camera, wand-length error of independently
//     triangulated ends (mean, RMS), image coverage (occupied cells of a grid);
//     warnings for too little coverage or too few frames;
//  6. optionally the ground frame from an L-frame recording (ground_frame.h).
// The result's world is camera 0's frame, or the L-frame's when one was given.
// Setup-time code: allocates, returns one-line errors.
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "camera/camera_model.h"
#include "core/expected.h"
#include "detect/detector_config.h"
#include "formats/wand_yaml.h"
#include "rigcal/bundle.h"
#include "rigcal/ground_frame.h"
#include "rigcal/wand_labeler.h"

namespace mocap::rigcal {

enum class IntrinsicsMode { kAuto, kRefine, kFixed };

struct RigCalOptions {
  detect::DetectorConfig detector{};
  double min_roundness = 0.95;  // of the expected roundness (detect_recording)
  WandLabelConfig label{};
  IntrinsicsMode intrinsics = IntrinsicsMode::kAuto;
  int min_frames = 30;            // fewer frames with the wand in both cameras: error
  int warn_frames = 200;          // fewer: warning
  double warn_coverage = 0.5;     // occupied fraction of the coverage grid below: warning
  double refine_coverage = 0.75;  // kAuto refines intrinsics only above this (both cameras)
  int refine_min_frames = 200;    // ... and with at least this many frames used
  int coverage_cols = 16;
  int coverage_rows = 12;
  double max_spacing_error = 0.02;  // measured inner-marker fraction vs wand.yaml
  std::uint64_t seed = 1;           // RANSAC
  GroundFrameOptions ground{};
};

// Blob centres (distorted pixels) per frame and camera.
using FrameBlobs = std::vector<std::array<std::vector<Vec2>, 2>>;

struct CameraQuality {
  std::string name;
  int frames_labelled = 0;
  std::array<int, 5> label_status{};  // count per LabelStatus
  double reprojection_rms_px = 0.0;
  double coverage = 0.0;             // occupied fraction of the grid
  std::vector<Vec2> wand_points_px;  // every labelled wand marker (for the coverage image)
};

struct RigCalResult {
  std::array<CameraModel, 2> cameras;  // world = camera 0 or the L-frame
  std::array<CameraQuality, 2> quality;
  int frames_total = 0;
  int frames_both = 0;  // wand labelled in both cameras
  int frames_used = 0;  // after the bundle adjustment's outlier rejection
  int essential_inliers = 0;
  double baseline_mm = 0.0;
  double wand_length_mean_error_mm = 0.0;
  double wand_length_rms_error_mm = 0.0;
  int wand_length_samples = 0;
  bool intrinsics_refined = false;
  std::string intrinsics_note;
  BundleStats bundle;
  bool has_ground = false;
  GroundFrameResult ground;
  std::vector<std::string> warnings;
};

// Detects blobs in every frame of a recording (cameras 0 and 1). Blobs that are merged,
// split or touch the border are left out, and so are blobs less round than
// min_roundness x the roundness a whole ball has at that place in the image (a ball's
// image is an ellipse stretched radially by perspective and squeezed by barrel
// distortion, expected_roundness()): a partly hidden marker has a biased centre.
// cams: the intrinsics for that expectation (the recording's rig.yaml when null).
Expected<FrameBlobs> detect_recording(const std::string& dir, const detect::DetectorConfig& cfg,
                                      double min_roundness = 0.0,
                                      const std::array<CameraModel, 2>* cams = nullptr);

// Minor/major axis ratio of a small ball's image centred at pixel px (first order:
// perspective stretch 1/cos(off-axis angle) and the distortion's radial/tangential
// scales).
double expected_roundness(const CameraModel& cam, const Vec2& px) noexcept;

// The calibration from already detected blobs. intrinsics: the two cameras' intrinsics
// (names and sizes must be set; extrinsics ignored). source names the recording in
// errors.
Expected<RigCalResult> calibrate_from_blobs(const FrameBlobs& blobs, const WandSpec& wand,
                                            const std::array<CameraModel, 2>& intrinsics,
                                            const RigCalOptions& options,
                                            const std::string& source);

// Sets the ground frame of a calibrated result from an L-frame recording's blobs.
Expected<void> set_ground_frame(RigCalResult& result, const FrameBlobs& lframe_blobs,
                                const LFrameSpec& lframe, const RigCalOptions& options,
                                const std::string& source);

}  // namespace mocap::rigcal
