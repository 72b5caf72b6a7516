// Design: the value types passed between the steps of `mocap discover` (docs/discover.md):
// the 3D points of every frame (frame_points.h), the short-term point tracks
// (point_tracker.h), and the options of every step in one struct with the stated
// bounds (speed, acceleration, point noise) from which the gates and the rigidity
// tolerances are derived. Offline, set-up style code: plain vectors, no hot path.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include "core/types.h"
#include "kinematics/linear_estimation.h"

namespace mocap::discover {

// The triangulated (unambiguous, whole-blob) 3D points of one frame, world frame, mm.
struct FramePoints {
  std::int64_t frame = 0;
  std::int64_t timestamp_ns = 0;
  std::vector<Vec3> X_world_mm;
};

struct PointSequence {
  std::vector<FramePoints> frames;
  int frames_missing_camera = 0;  // frames a camera did not deliver (no 3D points)
  int points_dropped = 0;         // ambiguous or merged-blob candidates left out
};

// A short-term track of one unlabelled point: X_world_mm[i] is its position in frame
// `first + i` (frame indices into PointSequence::frames); NaN where it was coasted over
// a short gap.
struct PointTrack {
  int first = 0;
  std::vector<Vec3> X_world_mm;
  int seen = 0;  // frames with a measurement

  int last() const noexcept { return first + static_cast<int>(X_world_mm.size()) - 1; }
  bool has(int f) const noexcept {
    return f >= first && f <= last() &&
           !std::isnan(X_world_mm[static_cast<std::size_t>(f - first)].x());
  }
  const Vec3& at(int f) const noexcept { return X_world_mm[static_cast<std::size_t>(f - first)]; }
};

struct DiscoverOptions {
  // Stated bounds.
  double max_speed_mm_per_s = 3000.0;    // fastest marker
  double max_accel_mm_per_s2 = 40000.0;  // fastest change of a marker's velocity (~4 g)
  // 1-sigma noise of a triangulated marker, per axis; 0: estimated from the recording's
  // own tracks (point_tracker.h estimate_point_noise), the default.
  double point_noise_mm = 0.0;
  double provisional_noise_mm = 0.15;  // gates of the first tracking pass (auto noise)
  // Systematic error a rigid pair's distance may show across the volume (rig calibration,
  // lens model), added to the rigidity bound.
  double model_error_mm = 0.1;
  double marker_diameter_mm = 12.0;  // written to targets.yaml; closest marker spacing
  // Tracking.
  int max_gap_frames = 1;    // a track coasts over this many missed frames
  double gate_sigmas = 4.0;  // noise part of every gate, in sigmas
  // Grouping (the frame counts and turns of the rigidity tests: derived, below).
  int min_track_frames = 10;               // shorter tracks are ignored (ghosts, glints)
  double static_tolerance_mm = 1.0;        // a point moving less is static
  double min_scene_speed_mm_per_s = 20.0;  // a point moving faster makes the scene "moving"
  int max_pair_frames = 400;               // pair statistics on at most this many frames
  // Joints (Eq. 2 / rank-5 hinge tests as in src/kinematics).
  kinematics::LinearOptions linear{20, 2.0, 0.25};
  double max_joint_residual_mm = 3.0;  // linear fit residual above this: not a joint
  int min_frames = 30;                 // fewer frames in the recording: error
  bool refine = true;                  // Ceres refinement of the joints

  // Derived tolerances (docs/discover.md). sigma: the stated or estimated point noise
  // (the provisional one while it is still to be estimated).
  double sigma_mm() const noexcept {
    return point_noise_mm > 0.0 ? point_noise_mm : provisional_noise_mm;
  }
  double pair_distance_std_mm() const noexcept {
    return 3.0 * std::sqrt(2.0) * sigma_mm() + model_error_mm;
  }
  double body_fit_tolerance_mm() const noexcept { return 4.0 * sigma_mm() + 0.2; }

  // Frame counts and motion of the rigidity tests, derived from the noise (see
  // docs/discover.md, "Frame counts and motion"; never tried on our scenes). A verdict
  // "rigid" needs n samples such that the statistic of a truly rigid pair (or point)
  // stays below its bound at z = 3 standard errors, the robust std of n Gaussian
  // samples having a relative standard error of kMadRelativeError / sqrt(n) (the MAD's
  // 37 % efficiency), and never fewer than kMinSamples (a median of 5 outvotes 2 bad
  // frames); and the frames must cover enough motion to tell rigid from non-rigid.
  static constexpr double kMadRelativeError = 1.17;
  static constexpr int kMinSamples = 5;
  static int frames_for(double noise_mm, double bound_mm) noexcept {
    if (!(bound_mm > noise_mm)) return 1000000;  // the bound cannot be met: no verdict
    const double root = 3.0 * kMadRelativeError * noise_mm / (bound_mm - noise_mm);
    return std::max(kMinSamples, static_cast<int>(std::ceil(root * root)));
  }
  // A pair's distance (noise sqrt(2) sigma) against pair_distance_std_mm().
  int min_covisible_frames() const noexcept {
    return frames_for(std::sqrt(2.0) * sigma_mm(), pair_distance_std_mm());
  }
  // A point mapped into a body frame (3D residual sqrt(3) sigma) against the fit tolerance.
  int min_placement_frames() const noexcept {
    return frames_for(std::sqrt(3.0) * sigma_mm(), body_fit_tolerance_mm());
  }
  // The smallest turn (rad) of a pair of length `length_mm` that makes its rigid verdict
  // mean something: had the two points been on bodies moving relatively by that much, the
  // distance would sweep +-length*turn/2 and more than 20 % of the frames would deviate
  // by more than 4 b (the non-rigid rule) once length*turn > 10 b.
  double min_pair_turn_rad(double length_mm) const noexcept {
    return 10.0 * pair_distance_std_mm() / std::max(length_mm, 1e-9);
  }
  // The smallest turn (rad) of a body that makes a point's fit at lever `lever_mm` from
  // the markers' centroid mean something: a point not carried by the body would sweep
  // +-lever*turn/2 in the body frame, an RMS of lever*turn/sqrt(12), beyond the fit
  // tolerance once lever*turn > sqrt(12) tol.
  double min_body_turn_rad(double lever_mm) const noexcept {
    return std::sqrt(12.0) * body_fit_tolerance_mm() / std::max(lever_mm, 1e-9);
  }
};

}  // namespace mocap::discover
