// Design: the rig calibration's decisions and figures after the bundle adjustment
// (internal to rig_calibrator.cpp, split out by concept): which cameras get their
// intrinsics refined (per camera: IntrinsicsMode, its coverage and its used frames) and
// the quality of the result (per camera: reprojection RMS, frames used, pose relative
// to camera 0; the wand-length error of independently triangulated ends: a frame seen
// by two cameras with the optimal two-view triangulation, by more with the N-view
// linear estimate refined by Gauss-Newton over its first kMaxCameras labelled cameras,
// stereo/nview.h; the warnings).
#pragma once

#include <string>
#include <vector>

#include "core/expected.h"
#include "rigcal/rig_calibrator.h"

namespace mocap::rigcal {

// Per camera: refine its intrinsics in a second bundle pass. Sets res.intrinsics_refined,
// res.intrinsics_note and quality[c].intrinsics_refined.
std::vector<bool> refine_decision(RigCalResult& res, const BundleStats& first_pass,
                                  const RigCalOptions& options);

// Fills the quality figures and warnings of res (cameras and bundle stats set).
Expected<void> fill_quality(RigCalResult& res, const WandSpec& wand,
                            const std::vector<WandFrame>& frames, const std::vector<bool>& use,
                            const RigCalOptions& options, const std::string& source);

}  // namespace mocap::rigcal
