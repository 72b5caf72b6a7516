// Design: the initial rig of 2..32 cameras for the bundle adjustment, built pairwise.
// Camera 0 is the world. Each other camera is initialised from a reference camera
// whose pose is already known: camera 0 when the two share at least min_shared_frames
// frames with the wand labelled in both, otherwise the initialised camera it shares the
// most frames with (a chain through the best-connected camera). For a pair (reference
// r, camera c): RANSAC essential matrix on the undistorted normalised wand points of
// the shared frames (essential.h), linear triangulation in r's frame, metric scale from
// the median end-to-end length against the wand's length, and the inner markers'
// measured positions checked against wand.yaml (a wrong spacing is an error). The pose
// of c then follows by composition: T_c_cam0 = T_c_r * T_r_cam0.
// Wand poses (camera 0's frame, metric) come from the first pair a frame took part in;
// frames seen only by cameras that were never paired with each other are triangulated
// from all their (at most kMaxCameras) labelled cameras (stereo/nview.h). A frame with
// an epipolar outlier or a point behind a camera in any pair is left out.
// With two cameras this is exactly the single pair's initialisation.
// Setup-time code: allocates, returns one-line errors.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "camera/camera_model.h"
#include "core/expected.h"
#include "formats/wand_yaml.h"
#include "rigcal/bundle.h"

namespace mocap::rigcal {

struct PairwiseInitOptions {
  int min_shared_frames = 30;       // fewer with camera 0: chain through another camera
  double max_spacing_error = 0.02;  // measured inner-marker fraction vs wand.yaml
  std::uint64_t seed = 1;           // RANSAC
};

struct PairwiseInit {
  std::vector<int> reference;          // per camera: initialised from (-1: camera 0)
  std::vector<int> shared_frames;      // per camera: frames shared with its reference
  std::vector<int> essential_inliers;  // per camera: inliers of its pair's RANSAC
  std::vector<WandPose> poses;         // per frame, camera 0's frame, mm
  std::vector<bool> use;               // per frame: usable start for the bundle
};

// Frames with the wand labelled in both cameras a and b.
int shared_frame_count(const std::vector<WandFrame>& frames, std::size_t a, std::size_t b);

// cams: intrinsics in (names set), extrinsics out (camera 0 at the identity). Errors
// name source and the camera (or the pair) concerned.
Expected<PairwiseInit> initialise_rig(const WandSpec& wand, const std::vector<WandFrame>& frames,
                                      std::vector<CameraModel>& cams,
                                      const PairwiseInitOptions& options,
                                      const std::string& source);

}  // namespace mocap::rigcal
