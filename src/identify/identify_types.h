// Design: the value types of rigid-target identification (the paper's Eq. 1 search):
// per-frame input points, the configuration validated at setup, the per-body output
// and the failure counters. Everything here is fixed-capacity and trivially usable in
// the hot path; capacities are compile-time bounds checked when the Identifier is
// created (more markers, bodies or points than these are refused at setup or counted
// as overflow per frame, never allocated for).
#pragma once

#include <array>
#include <cstdint>

#include "core/camera_set.h"
#include "core/types.h"

namespace mocap {

inline constexpr int kMaxMarkers = 16;      // markers per target
inline constexpr int kMaxBodies = 32;       // targets per Identifier (the whole robot, or two)
inline constexpr int kMaxPoints = 512;      // measured 3D points per frame (hard bound)
inline constexpr int kMaxBestPairs = 1024;  // bound of IdentifyConfig::best_pairs

// One triangulated 3D point. blob_index[c] is the blob of camera c of the rig it was
// triangulated from, -1 if unknown. Two points sharing a blob in the same camera are
// mutually exclusive (epipolar ambiguity): a solution uses at most one of them.
struct MeasuredPoint {
  Vec3 X_world = Vec3::Zero();  // mm
  BlobRefs blob_index;          // per camera of the rig; -1: not seen by that camera
  // The image of the marker does not look whole in some camera (partly occluded, split
  // from a merged blob, cut by the border): its centroid may be biased. Such a point is
  // identified like any other but left out of the pose fit while 3 whole markers remain.
  bool partial = false;
};

enum class MotionModel { kConstantPose, kConstantVelocity };
enum class AmbiguityPolicy { kWarn, kReject };

struct IdentifyConfig {
  // --- the paper's search (Section 2.1, Eq. 1) ---
  double t_mm = 5.0;        // threshold t: pair discrepancy and every residual < t
  int best_pairs = 50;      // 2-matchings kept in the priority queue (the one heuristic)
  double score_base = 1.5;  // penalty base: score = |r| * base^(k-m) / m
  int min_markers = 3;      // m >= this (>= 3: Umeyama needs 3 points)
  // Expected per-marker noise sigma_0: the score uses sqrt(|r|^2 + m*sigma_0^2) instead of
  // |r|, so that a small subset cannot win merely because a 3-point fit absorbs 6 of its 9
  // noise degrees of freedom (0 gives the paper's literal score; see identification.md).
  double residual_floor_mm = 0.5;
  int max_points = kMaxPoints;  // per-frame capacity (<= kMaxPoints); extra points dropped
  // Cameras of the rig (1..kMaxCameras; FrameProcessor sets the rig's): sizes the
  // per-camera blob occupancy. Views of cameras at or above it are ignored.
  int cameras = kMaxCameras;
  int max_search_nodes = 20000;  // per target and frame; hitting it is counted
  // A solution is accepted only if every solution that contradicts it (a point on another
  // marker, a marker on another point) scores at least ambiguity_ratio times worse;
  // otherwise the body is not reported in this frame (never a coin-flip identity).
  // <= 1 disables the check.
  double ambiguity_ratio = 1.5;
  // --- consistency test (consistency.h) ---
  // Expected per-coordinate noise of a clean 3D marker point plus the target's model error
  // (mm). A solution whose residual exceeds what this noise explains at
  // `consistency_confidence` loses its worst markers (leave-one-out) or is rejected; this is
  // what keeps partly occluded markers and stray points from passing the wide gate t.
  // Set it from the `rms_mm` of a static recording (about 1.2 x that value); 0 disables.
  double point_sigma_mm = 0.2;
  double consistency_confidence = 0.9999;  // in [0.99, 0.999999]
  // Per-coordinate noise assumed for a partial marker when it must join a pose fit
  // (fewer than 3 whole markers, or exclude_partial_markers = false): the bias of a partly
  // hidden marker's centroid, typically 0.3-3 mm. >= point_sigma_mm; 0: same as whole.
  double partial_sigma_mm = 1.0;
  // Fit the pose on whole markers only while at least 3 are matched (MeasuredPoint::partial).
  bool exclude_partial_markers = true;
  // A body is reported only with at least this many whole (not partial) markers matched,
  // like the circularity filters of commercial trackers; 0 also reports poses that rest on
  // partial markers (better coverage under heavy occlusion, biased by up to a few mm).
  int min_whole_markers = 3;
  // --- temporal path ---
  bool temporal = true;  // use the previous pose as a prior
  MotionModel motion_model = MotionModel::kConstantVelocity;
  // The gate around each predicted marker is derived from the limits below, the time
  // since the body was last seen and point_sigma_mm (motion.h); warm_gate_mm is the gate
  // only when no limit bounds the motion (speed limits and acceleration all <= 0).
  double warm_gate_mm = 15.0;
  // Nearest-neighbour matches (one point in every gate) need this many markers; fewer, or
  // several points in a gate: the Eq. 1 search restricted to the gates decides (>= 3).
  int warm_min_markers = 4;
  double max_prior_age_s = 0.25;  // older prior -> full search
  // Stated limits of the motion: the fastest marker, the fastest rotation (<= 0: none).
  double max_speed_mm_per_s = 10000.0;
  double max_angular_speed_deg_per_s = 3600.0;
  // Largest acceleration of a marker (mm/s^2) that the constant-velocity gate allows;
  // 0: max_speed * max_angular_speed (a marker at the speed limit turning at the limit).
  double max_acceleration_mm_per_s2 = 0.0;
  // --- load time ---
  AmbiguityPolicy ambiguity_policy = AmbiguityPolicy::kWarn;
};

struct BodyPose {
  bool found = false;
  bool from_prior = false;  // found by the temporal path (validated), not the full search
  bool from_chain = false;  // solved through the kinematic chain (track/chain_solver.h)
  Iso3 T_world_body = Iso3::Identity();
  int markers = 0;      // matched markers m
  double rms_mm = 0.0;  // RMS residual of the least-squares fit over the m markers
  double score = 0.0;   // Eq. 1 score of the solution
  // Input index of the point matched to each model marker, -1 if unmatched.
  std::array<std::int16_t, kMaxMarkers> point_index_of_marker{};
};

// One entry per target, in the order of TargetSet::bodies.
struct BodyPoses {
  int count = 0;  // number of targets
  int found = 0;  // how many of them were found this frame
  std::array<BodyPose, kMaxBodies> bodies{};
};

struct IdentifyCounters {
  std::uint64_t frames = 0;
  std::uint64_t bodies_found = 0;
  std::uint64_t full_searches = 0;   // Eq. 1 searches run (including re-searches)
  std::uint64_t warm_accepted = 0;   // bodies found by the temporal path
  std::uint64_t warm_fallbacks = 0;  // prior present but validation failed -> search
  // of warm_accepted: decided by the search within the gates (several points in a gate,
  // or fewer than warm_min_markers), e.g. a triangle that also fits elsewhere in the target
  std::uint64_t continuity_resolved = 0;
  std::uint64_t conflict_researches = 0;  // a body lost points to a better body: re-searched
  std::uint64_t velocity_rejects = 0;     // pose jumped beyond the limits: track dropped
  std::uint64_t jump_reboots = 0;         // of those, re-acquired by the cold solution (same frame)
  std::uint64_t point_overflow = 0;       // points beyond max_points dropped (count of points)
  std::uint64_t invalid_points = 0;       // non-finite points ignored
  std::uint64_t node_limit_hits = 0;      // searches stopped at max_search_nodes
  std::uint64_t bad_timestamps = 0;       // timestamp not increasing: prior dropped
  std::uint64_t ambiguous_rejects = 0;    // best solution not clearly better than a rival
  std::uint64_t outlier_markers = 0;      // matched markers dropped by the consistency test
  std::uint64_t consistency_rejects = 0;  // solutions rejected by the consistency test
  std::uint64_t partial_excluded = 0;     // matched partial markers left out of a pose fit
  std::uint64_t partial_rejects = 0;      // solutions with fewer than min_whole_markers whole
};

}  // namespace mocap
