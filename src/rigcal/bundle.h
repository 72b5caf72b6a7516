// Design: bundle adjustment of the stereo rig from wand observations (Ceres). The world
// is camera 0's frame (its pose is held constant: the gauge); camera 1's pose is an
// angle-axis rotation plus a translation. Each wand frame is the position A of marker 0
// and a unit direction d (SphereManifold), so marker k sits exactly at A + s_k d: the
// wand's length fixes the metric scale and collinearity is built in. Residuals are the
// reprojection errors in the real (distorted) images through the same model as
// camera_model.h (OpenCV's 5-parameter distortion), with a Huber loss. Intrinsics
// [fx fy cx cy k1 k2 p1 p2 k3] are constant unless refine_intrinsics; then fx, fy, cx,
// cy, k1, k2 are estimated and p1, p2, k3 stay as given (weakly observable from a wand).
// Frames with a residual far above the RMS are dropped and the problem solved again.
// Linear solver: dense Schur complement with the wand poses eliminated first.
#pragma once

#include <array>
#include <vector>

#include "camera/camera_model.h"
#include "core/expected.h"
#include "formats/wand_yaml.h"

namespace mocap::rigcal {

// One frame with the wand labelled in both cameras (distorted pixels, marker order).
struct WandFrame {
  int frame = 0;
  std::array<std::vector<Vec2>, 2> px;
};

// Wand pose in camera 0's frame: marker k at A + (s_k - s_0) d.
struct WandPose {
  Vec3 A = Vec3::Zero();
  Vec3 d = Vec3::UnitX();
};

struct BundleOptions {
  bool refine_intrinsics = false;
  double huber_px = 1.0;
  // Frames with a marker residual above clamp(outlier_sigmas x RMS, outlier_min_px,
  // outlier_px) after a round are dropped.
  double outlier_px = 2.0;
  double outlier_min_px = 0.3;
  double outlier_sigmas = 5.0;
  int max_iterations = 100;
  int rounds = 2;  // solve, drop outliers, solve again
};

struct BundleStats {
  std::array<double, 2> rms_px{};  // reprojection RMS per camera over used frames
  int frames_used = 0;
  int frames_dropped = 0;
  int iterations = 0;
  bool converged = false;
};

// Reprojection error vectors of one frame (2 cameras x N markers); false if behind.
bool wand_residuals(const std::array<CameraModel, 2>& cams, const WandSpec& wand,
                    const WandFrame& obs, const WandPose& pose, std::vector<double>& err_px);

// cams: initial values in, estimates out (cams[0] must be at the identity pose).
// poses: one per frame, initial values in, estimates out. use: which frames take part
// (updated: outliers set false).
Expected<BundleStats> bundle_adjust(const WandSpec& wand, const std::vector<WandFrame>& frames,
                                    std::vector<bool>& use, std::array<CameraModel, 2>& cams,
                                    std::vector<WandPose>& poses, const BundleOptions& options);

}  // namespace mocap::rigcal
