// Design: bundle adjustment of a rig of 2..32 cameras from wand observations (Ceres), one
// joint problem over all cameras. The world is camera 0's frame (its pose is held
// constant: the gauge); every other camera's pose is an angle-axis rotation plus a
// translation. Each wand frame is the position A of marker 0
// and a unit direction d (SphereManifold), so marker k sits exactly at A + s_k d: the
// wand's length fixes the metric scale and collinearity is built in. Residuals are the
// reprojection errors in the real (distorted) images through the same model as
// camera_model.h (OpenCV's 5-parameter distortion), each weighed by its centre's
// covariance relative to the recording's median centre (when the frames carry them),
// with a Huber loss. Intrinsics
// [fx fy cx cy k1 k2 p1 p2 k3] are constant unless refine_intrinsics; then fx, fy, cx,
// cy, k1, k2 are estimated and p1, p2, k3 stay as given (weakly observable from a wand);
// this is decided per camera (refine_camera). A frame takes part when the wand is
// labelled in at least two cameras; a camera where it is not labelled adds no residual.
// Frames with a residual far above the RMS are dropped and the problem solved again.
// Linear solver: dense Schur complement with the wand poses eliminated first.
#pragma once

#include <vector>

#include "camera/camera_model.h"
#include "core/expected.h"
#include "formats/wand_yaml.h"

namespace mocap::rigcal {

// Blob centres (distorted pixels) per frame and camera: blobs[f][c], every frame with
// one entry per camera of the rig.
using FrameBlobs = std::vector<std::vector<std::vector<Vec2>>>;
// What the detection knows of one centre of a FrameBlobs.
struct CentreInfo {
  Eigen::Matrix2d cov_px2 = Eigen::Matrix2d::Zero();  // the edge fit's (zero: not known)
  bool partly_hidden = false;  // less round than a whole ball there: its rim is cut
};
// Per centre of a FrameBlobs, the same shape.
using FrameCentreInfo = std::vector<std::vector<std::vector<CentreInfo>>>;

// One frame of the wand (distorted pixels, marker order). px has one entry per camera;
// an empty entry: the wand is not labelled in that camera. info: empty, or as px.
struct WandFrame {
  int frame = 0;
  std::vector<std::vector<Vec2>> px;
  std::vector<std::vector<CentreInfo>> info;
  int cameras_labelled() const noexcept;
};

// Wand pose in camera 0's frame: marker k at A + (s_k - s_0) d.
struct WandPose {
  Vec3 A = Vec3::Zero();
  Vec3 d = Vec3::UnitX();
};

struct BundleOptions {
  bool refine_intrinsics = false;
  // Per camera; empty: every camera as refine_intrinsics says.
  std::vector<bool> refine_camera;
  // Each residual weighed by its centre's covariance (WandFrame::info) relative to
  // the median centre's, so a typical centre's residual stays in pixels; a centre
  // without one weighs as the median. Off, or no covariances: all weigh the same.
  bool weight_by_covariance = true;
  double huber_px = 1.0;
  // Frames with a marker residual above clamp(outlier_sigmas x RMS, outlier_min_px,
  // outlier_px) after a round are dropped (residuals weighed as in the adjustment, so
  // a noisy centre is held to its own noise).
  double outlier_px = 2.0;
  double outlier_min_px = 0.3;
  double outlier_sigmas = 5.0;
  int max_iterations = 100;
  int rounds = 2;  // solve, drop outliers, solve again
};

struct BundleStats {
  std::vector<double> rms_px;          // reprojection RMS per camera over the used frames' whole
                                       // balls (all balls when a camera has no whole one)
  std::vector<int> frames_per_camera;  // used frames labelled in each camera
  int frames_used = 0;
  int frames_dropped = 0;
  int iterations = 0;
  bool converged = false;
};

// One marker's reprojection error in one camera.
struct WandResidual {
  double px = 0.0;        // |projection - centre| in pixels
  double weighted = 0.0;  // |W (projection - centre)|: in units of a median centre's noise
                          // (= px without weights)
  int camera = 0;
  bool partly_hidden = false;  // the centre's (WandFrame::info)
};

// The reprojection errors of one frame, labelled cameras in order x N markers. weight:
// per camera and marker (as WandFrame::px), or empty (weighted = px). False if a point
// is behind a camera.
bool wand_residuals(const std::vector<CameraModel>& cams, const WandSpec& wand,
                    const WandFrame& obs, const WandPose& pose,
                    const std::vector<std::vector<Eigen::Matrix2d>>& weight,
                    std::vector<WandResidual>& out);

// cams: initial values in, estimates out (cams[0] must be at the identity pose).
// poses: one per frame, initial values in, estimates out. use: which frames take part
// (updated: outliers and frames labelled in fewer than two cameras set false). Every
// frame's px must have cams.size() entries.
Expected<BundleStats> bundle_adjust(const WandSpec& wand, const std::vector<WandFrame>& frames,
                                    std::vector<bool>& use, std::vector<CameraModel>& cams,
                                    std::vector<WandPose>& poses, const BundleOptions& options);

}  // namespace mocap::rigcal
