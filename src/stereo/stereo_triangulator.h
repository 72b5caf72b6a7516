// Design: the stereo stage. Per frame it takes the 2D blob centroids (distorted pixels)
// of an ordered camera pair (a, b), undistorts them, pairs them by symmetric epipolar
// distance, triangulates every pair optimally (niter2, two_view.h) and emits one 3D
// candidate per accepted pair.
//   Matching rule: a pair (i, j) is kept when BOTH epipolar distances, measured in
//   undistorted pixels (d_a: blob i to the epipolar line of j in image a; d_b likewise)
//   are <= epipolar_tolerance_px, the triangulated point lies in front of both cameras
//   (cheirality) at depths (z in each camera) within [min_depth_mm, max_depth_mm], and
//   its RMS reprojection error in the real images is <= max_reproj_px.
//   Ambiguity policy: EVERY pair passing the rule is kept; each candidate records its
//   blob index per camera, and candidates sharing a blob with another are flagged
//   `ambiguous`. Nothing is silently dropped except for capacity, which is counted.
//   Search: the blobs of camera b are sorted by the angle of their epipolar plane about
//   the baseline (a pseudo-angle, monotone in it: no trigonometry per blob); a blob of
//   camera a only visits the b-blobs whose plane angle lies in a window that provably
//   contains every pair within tolerance, O((n+m) log m + k). Given SettledBlobs (an N-view
//   rig's later pairs), a settled a-blob searches a copy of the keys holding only the
//   unsettled b-blobs: two settled blobs are never looked at.
//   MatchMethod::kExhaustive (all n*m pairs) gives the same set; kept for testing and
//   benchmarks.
// Capacity is fixed in create(); process() is noexcept and allocation-free. Failures
// and overflows become counters. For N cameras, run one triangulator per camera pair
// (pairs enumerated by the caller); blob_index is indexed by the rig's camera index.
// With N cameras, undistort each camera's blobs once per frame (BlobUndistorter,
// undistorted_blobs.h) and pass the views: the same result without undistorting every
// camera N - 1 times.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "camera/camera_model.h"
#include "core/expected.h"
#include "stereo/stereo_types.h"
#include "stereo/two_view.h"
#include "stereo/undistorted_blobs.h"

namespace mocap {

enum class MatchMethod : std::uint8_t { kSortedSweep, kExhaustive };

struct StereoConfig {
  double epipolar_tolerance_px = 2.0;  // symmetric, undistorted pixels
  double max_reproj_px = 2.0;          // RMS over the two views, real pixels
  double min_depth_mm = 100.0;         // z in each camera
  double max_depth_mm = 20000.0;
  int max_points_per_camera = 256;  // further blobs of a frame are ignored (counted)
  int max_candidates = 1024;        // further candidates are dropped (counted)
  MatchMethod method = MatchMethod::kSortedSweep;
};

// Cumulative since create() or reset_counters(). Index [0] is camera a, [1] camera b.
struct StereoCounters {
  std::uint64_t frames = 0;
  std::array<std::uint64_t, 2> points_in{};         // blobs received
  std::array<std::uint64_t, 2> points_overflow{};   // blobs beyond max_points_per_camera
  std::array<std::uint64_t, 2> undistort_failed{};  // blobs whose undistortion failed
  std::uint64_t pairs_in_tolerance = 0;             // pairs passing the epipolar test
  std::uint64_t settled_blobs = 0;                  // a-blobs settled: search open b-blobs only
  std::uint64_t rejected_degenerate = 0;            // parallel rays (on the baseline / at infinity)
  std::uint64_t rejected_cheirality = 0;            // behind a camera
  std::uint64_t rejected_depth = 0;                 // outside [min_depth_mm, max_depth_mm]
  std::uint64_t rejected_reproj = 0;                // reprojection error above max_reproj_px
  std::uint64_t candidates = 0;                     // accepted candidates (including dropped ones)
  std::uint64_t ambiguous = 0;                      // emitted candidates flagged ambiguous
  std::uint64_t candidate_overflow = 0;             // accepted but dropped: output full
  std::uint64_t bad_input = 0;                      // null pointer with n > 0 or n < 0

  // Adds the counters of another camera pair of the same rig (the rig's total over its
  // pairs): every count is summed, except `frames`, the larger of the two (the pairs
  // see the same frames; a frame is not counted once per pair).
  StereoCounters& operator+=(const StereoCounters& o) noexcept {
    frames = frames > o.frames ? frames : o.frames;
    for (std::size_t i = 0; i < 2; ++i) {
      points_in[i] += o.points_in[i];
      points_overflow[i] += o.points_overflow[i];
      undistort_failed[i] += o.undistort_failed[i];
    }
    pairs_in_tolerance += o.pairs_in_tolerance;
    settled_blobs += o.settled_blobs;
    rejected_degenerate += o.rejected_degenerate;
    rejected_cheirality += o.rejected_cheirality;
    rejected_depth += o.rejected_depth;
    rejected_reproj += o.rejected_reproj;
    candidates += o.candidates;
    ambiguous += o.ambiguous;
    candidate_overflow += o.candidate_overflow;
    bad_input += o.bad_input;
    return *this;
  }
};

class StereoTriangulator {
 public:
  // Setup: validates the configuration and the pair (cam_a, cam_b are indices into
  // rig.cameras, distinct, < kMaxCameras) and allocates the workspace.
  static Expected<StereoTriangulator> create(const Rig& rig, const StereoConfig& config,
                                             int cam_a = 0, int cam_b = 1);

  // One frame: px_a[0..n_a) and px_b[0..n_b) are blob centroids in distorted pixels.
  // Clears `out` and fills it with candidates (capacity min(out.capacity(),
  // max_candidates)). Returns false when something was dropped this frame (blob or
  // candidate overflow, bad input); the candidates written are valid either way.
  bool process(const Vec2* px_a, int n_a, const Vec2* px_b, int n_b, PointList& out,
               SettledBlobs settled = {}) noexcept;
  // The same from blobs undistorted once per camera and frame: `a` of camera_a(), `b` of
  // camera_b() (views of a BlobUndistorter of that rig camera with a capacity of at least
  // max_points_per_camera). Identical result and counters. `settled`: pairs not to try.
  bool process(const UndistortedBlobs& a, const UndistortedBlobs& b, PointList& out,
               SettledBlobs settled = {}) noexcept;

  const StereoCounters& counters() const noexcept { return counters_; }
  void reset_counters() noexcept { counters_ = StereoCounters{}; }
  const StereoConfig& config() const noexcept { return config_; }
  const StereoGeometry& geometry() const noexcept { return geometry_; }
  int camera_a() const noexcept { return cam_a_; }
  int camera_b() const noexcept { return cam_b_; }

 private:
  struct Observation {
    Vec2 px;     // distorted pixels (input)
    Vec2 s;      // pixel-scaled undistorted coordinates (fx x', fy y')
    double key;  // the epipolar plane's angle about the baseline as a pseudo-angle
    // Camera a only: the window of keys [lo, hi] (lo > hi: it wraps through 0, i.e.
    // [0, hi] and [lo, 2]); whole: every plane (the blob's ray is near the baseline).
    double lo, hi;
    bool whole;
    bool valid;
  };
  struct SortKey {
    double key;
    int index;
  };

  StereoTriangulator() = default;
  // The observations of one camera's blobs; a blob with skip[i] >= 0 (skip non-null) is
  // marked valid only, with nothing computed (a settled a-blob with no b-blob to search).
  void prepare(const UndistortedBlobs& blobs, int n, int camera, std::vector<Observation>& obs,
               const int* skip = nullptr) noexcept;
  void try_pair(int i, int j, PointList& out, int capacity) noexcept;
  // Tries blob i of camera a with the b-blobs keys[0..n) whose key lies in [lo, hi].
  void scan_range(int i, const SortKey* keys, int n, double lo, double hi, PointList& out,
                  int capacity) noexcept;

  StereoConfig config_;
  CameraModel cam_a_model_;
  CameraModel cam_b_model_;
  StereoGeometry geometry_;
  Vec3 plane_u_0_ = Vec3::Zero();  // orthonormal pair perpendicular to the baseline
  Vec3 plane_v_0_ = Vec3::Zero();
  Vec3 plane_u_1_ = Vec3::Zero();  // the same pair in camera-b coordinates (R_10 u, R_10 v)
  Vec3 plane_v_1_ = Vec3::Zero();
  int cam_a_ = 0;
  int cam_b_ = 1;
  BlobUndistorter undistort_a_;  // for process() from distorted pixels
  BlobUndistorter undistort_b_;
  std::vector<Observation> obs_a_;
  std::vector<Observation> obs_b_;
  std::vector<SortKey> keys_b_;
  std::vector<SortKey> keys_b_open_;  // keys_b_'s unsettled blobs (settled a-blobs search these)
  std::vector<std::uint16_t> use_a_;
  std::vector<std::uint16_t> use_b_;
  SettledBlobs settled_;  // this frame's (process())
  bool frame_overflow_ = false;
  StereoCounters counters_;
};

}  // namespace mocap
