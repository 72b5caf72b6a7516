// Design: the value types the stereo stage hands to identification.
// A Point3 is one 3D *candidate*: it records, for every camera of the rig, which 2D
// blob it was triangulated from (-1 when that camera is not used), so that the
// identification stage knows which candidates are mutually exclusive (they share a
// blob in some camera). Candidates whose blob is shared with another candidate are
// flagged `ambiguous`; the stereo stage never silently picks one of them.
// PointList is the core BoundedList of candidates: capacity set once at setup, the hot
// path only clears and appends (push_back returns false when full, never allocates).
#pragma once

#include <array>
#include <cstdint>

#include "core/bounded_list.h"
#include "core/camera_set.h"
#include "core/types.h"

namespace mocap {

// Camera pairs for rigs with more than two cameras: one StereoTriangulator per pair.
inline constexpr int kMaxCameraPairs = kMaxCameras * (kMaxCameras - 1) / 2;
struct CameraPair {
  int a = 0;
  int b = 1;
};
// All pairs (a < b) of the first min(n_cameras, kMaxCameras) cameras in lexicographic
// order ((0,1), (0,2), ..., (1,2), ...); returns how many were written.
inline int enumerate_camera_pairs(int n_cameras,
                                  std::array<CameraPair, kMaxCameraPairs>& pairs) noexcept {
  const int n = n_cameras < kMaxCameras ? n_cameras : kMaxCameras;
  int count = 0;
  for (int a = 0; a < n; ++a)
    for (int b = a + 1; b < n; ++b) pairs[static_cast<std::size_t>(count++)] = CameraPair{a, b};
  return count;
}

struct Point3 {
  Vec3 X_world = Vec3::Zero();  // mm, world frame
  double reproj_px = 0.0;       // RMS reprojection error over the used views, real pixels
  double epipolar_px = 0.0;     // max of the two symmetric epipolar distances (undistorted px)
  BlobRefs blob_index;          // blob per camera of the rig; -1: camera unused
  bool ambiguous = false;       // shares a blob with another candidate of the same frame
  // Reported as a marker (points.csv): the stereo stage reports exactly the unambiguous
  // candidates; track/point_selection.h then resolves the ambiguous ones by evidence.
  bool reported = false;
};

// Candidates of one frame, indexed by int (the indices travel in int fields).
using PointList = BoundedList<Point3, int>;

// Blobs of the pair's cameras that earlier pairs of the frame already settled (the N-view
// merge, multiview.h "Settled blobs"): per blob (the first max_points_per_camera of each
// camera) the point that settled it, -1: none. A pair of two settled blobs is no
// candidate (the stereo stage never looks at it: a settled a-blob searches the unsettled
// b-blobs only, counted in settled_blobs; the merge, given lists, counts it in settled):
// it is that point again, or a ghost of two points. nullptr: nothing settled.
inline bool settled_pair(int settled_a, int settled_b) noexcept {
  return settled_a >= 0 && settled_b >= 0;
}
struct SettledBlobs {
  const int* a = nullptr;
  const int* b = nullptr;
};

}  // namespace mocap
