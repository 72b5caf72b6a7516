// Design: which 3D candidates of a frame are reported as markers (points.csv, the
// live outputs). The stereo stage keeps EVERY pair within the epipolar tolerance; two
// markers near one epipolar plane give four candidates sharing blobs (two true, two
// ghosts). Dropping all of them loses bright, unoccluded markers, so the ambiguity is
// resolved with more evidence, strongest first, one candidate per blob:
//  tier 0  used by a body that identification found (it already treats candidates
//          sharing a blob as mutually exclusive);
//  tier 1  unambiguous (no other candidate shares its blobs);
//  tier 2  temporal continuity: within the gate of a point reported in the previous
//          frame, gate = max_speed_mm_per_s * dt + 4 * point_sigma_mm; nearest first;
//  tier 3  mutual best epipolar fit: ascending symmetric epipolar distance (the
//          greedy order makes every accepted pair the mutual best of the blobs still
//          free).
// Within a tier a candidate is reported only when none of its blobs is taken yet.
// create() allocates; select() is noexcept and allocation-free (std::sort on a
// preallocated index array). Temporal state: the previous frame's reported points.
#pragma once

#include <cstdint>
#include <vector>

#include "core/expected.h"
#include "identify/identify_types.h"
#include "stereo/stereo_types.h"

namespace mocap {

struct PointSelectionConfig {
  bool temporal = true;
  double max_speed_mm_per_s = 3000.0;  // a marker moves at most this fast
  double point_sigma_mm = 0.5;         // 3D noise of a triangulated marker
  double max_gap_s = 0.1;              // older previous frames give no temporal evidence
};

struct PointSelectionStats {
  int by_body = 0;
  int unambiguous = 0;
  int by_continuity = 0;
  int by_epipolar = 0;
  int rejected = 0;  // ambiguous candidates whose blob went to a better candidate
};

class PointSelector {
 public:
  PointSelector() = default;
  // `cameras`: the rig's camera count (1..kMaxCameras), which sizes the blob table; a
  // view of a camera at or above it counts as a blob beyond max_blobs_per_camera.
  static Expected<PointSelector> create(int max_candidates, int max_blobs_per_camera,
                                        const PointSelectionConfig& config,
                                        int cameras = kMaxCameras);

  // Sets Point3::reported on every candidate of `points`. `poses` are this frame's
  // identification results (their point indices refer to `points`).
  PointSelectionStats select(const BodyPoses& poses, std::int64_t timestamp_ns,
                             PointList& points) noexcept;
  void reset() noexcept { prev_count_ = 0; }

 private:
  struct Key {
    double value;
    int index;
  };
  bool free_blobs(const Point3& p) const noexcept;
  void take(Point3& p) noexcept;

  PointSelectionConfig config_;
  int max_blobs_ = 0;
  int cameras_ = 0;
  std::vector<std::uint8_t> taken_;  // cameras_ x max_blobs_
  std::vector<Key> keys_;
  std::vector<Vec3> prev_;
  int prev_count_ = 0;
  std::int64_t prev_t_ns_ = 0;
};

}  // namespace mocap
