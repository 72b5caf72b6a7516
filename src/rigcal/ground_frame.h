// Design: the ground (world) frame from an L-frame recording. With the calibrated rig
// (2..32 cameras), every frame's blobs are matched across each pair of cameras by the
// epipolar constraint and triangulated (optimal two-view triangulation,
// stereo/two_view.h); the L-frame is static, so the 3D points of all pairs are
// clustered over the frames (a marker seen by k cameras adds up to k(k-1)/2 points per
// frame to its cluster, averaging the pairs) and clusters that got a point in at least
// half of the frames are kept (ghost matches of blobs sharing an epipolar line are kept too
// and lose in the next step). Every ordered choice of clusters for the L-frame's
// markers is scored by a rigid fit (Eigen::umeyama, no scale) of the L-frame's markers
// onto them; the best fit gives T_cam0_lframe. A fit worse than max_rms_mm is an error
// (wrong L-frame file or markers not seen).
#pragma once

#include <string>
#include <vector>

#include "camera/camera_model.h"
#include "core/expected.h"
#include "formats/wand_yaml.h"
#include "rigcal/bundle.h"

namespace mocap::rigcal {

struct GroundFrameOptions {
  double max_epipolar_px = 2.0;
  double cluster_radius_mm = 5.0;
  double max_rms_mm = 3.0;
};

struct GroundFrameResult {
  Iso3 T_cam0_lframe = Iso3::Identity();  // X_cam0 = T * X_lframe
  double rms_mm = 0.0;                    // residual of the rigid fit
  int frames = 0;
  std::vector<Vec3> markers_cam0;  // the matched cluster centres, L-frame marker order
};

// blobs[f][c]: distorted pixel centres of camera c in frame f (one entry per camera).
// cams: world = camera 0.
Expected<GroundFrameResult> estimate_ground_frame(const LFrameSpec& lframe, const FrameBlobs& blobs,
                                                  const std::vector<CameraModel>& cams,
                                                  const GroundFrameOptions& options,
                                                  const std::string& source);

// The rig re-expressed with the L-frame as world: X_cam = R_cam_cam0 (T X_lframe) + t.
void apply_ground_frame(std::vector<CameraModel>& cams, const Iso3& T_cam0_lframe);

}  // namespace mocap::rigcal
