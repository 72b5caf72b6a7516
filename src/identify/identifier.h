// Design: the per-frame rigid-body identification stage. Immutable models plus a
// preallocated workspace (Ceres/Pinocchio style): create() validates the configuration
// and the targets, precomputes the models, runs the ambiguity detection and sizes every
// buffer; identify() is noexcept and allocation-free.
// Per frame:
//  1. temporal path (bodies with a recent pose; motion.h): predict the pose (constant
//     velocity: the last screw motion continued; or constant pose), collect the available
//     points within the gate around each predicted marker (the gate: the prediction error
//     the stated limits allow over the time since the body was last seen, plus noise).
//     One point in every gate and m >= warm_min_markers: nearest-neighbour match, refit
//     (Umeyama), a second pass within min(t, gate) of the refit. Otherwise, or if that
//     fails, the Eq. 1 search restricted to the gates (identification by continuity):
//     its winner is accepted when no contradicting placement within the gates comes
//     within ambiguity_ratio (a triangle that also fits another triangle of the target
//     elsewhere is decided by where the body was). Validation: consistency test, speed
//     limits; two warm bodies that share a point (or a blob) both fall back.
//  2. full search (TargetSearch, the paper's Eq. 1) for the other bodies, on the points
//     the temporal path did not take.
//  3. conflicts: the pending body with the best (lowest) score whose solution is unique
//     (no contradicting rival within ambiguity_ratio) is accepted first and takes its
//     points (and every point sharing a blob with them); a body whose solution or rival
//     lost a point is searched again without the taken points; repeat. Bodies left
//     ambiguous when nothing more can change are not reported (counted).
//  Every solution (and the rival that decides its uniqueness) passes the consistency test
//  of consistency.h first: outlier markers dropped, solutions the noise cannot explain
//  rejected.
//  4. a cold pose beyond the speed limits since the body was last seen (a jump, or a wrong
//     identity of the track) drops the body's track (counted); the solution, a fresh full
//     search of this frame that passed the ambiguity and consistency tests, re-acquires
//     ("boots") the body in the same frame.
// Cost: the temporal path queries a grid of the points (FramePoints), so a tracked body
// costs the same whatever the number of bodies; only the bodies it did not take are
// searched, over the neighbours of each seed's point.
#pragma once

#include <string>
#include <vector>

#include "core/expected.h"
#include "formats/targets_yaml.h"
#include "identify/ambiguity.h"
#include "identify/consistency.h"
#include "identify/frame_points.h"
#include "identify/identify_types.h"
#include "identify/motion.h"
#include "identify/target_model.h"
#include "identify/target_search.h"

namespace mocap {

class Identifier {
 public:
  // Errors (one line): invalid configuration, no body, more than kMaxBodies bodies, a
  // body with too few/many markers or markers closer than t, and, with
  // AmbiguityPolicy::kReject, the first ambiguity found.
  static Expected<Identifier> create(const TargetSet& targets, const IdentifyConfig& config = {});

  // Identifies every target among pts[0..n) (world frame, mm; points beyond
  // config.max_points are dropped and counted). timestamp_ns: capture time of the frame
  // (used by the temporal path and the speed limits). out.bodies[b] follows
  // TargetSet::bodies; point_index_of_marker holds indices into pts. Returns true when
  // every body was found.
  bool identify(const MeasuredPoint* pts, int n, std::int64_t timestamp_ns,
                BodyPoses& out) noexcept;

  // Forgets every previous pose (the next frame is identified by full searches only).
  void reset() noexcept;

  const IdentifyCounters& counters() const noexcept { return counters_; }
  // One line per ambiguity found at create() (empty when none).
  const std::vector<std::string>& warnings() const noexcept { return warnings_; }
  const std::vector<AmbiguityFinding>& ambiguities() const noexcept { return ambiguities_; }
  int body_count() const noexcept { return static_cast<int>(models_.size()); }
  const TargetModel& model(int body) const noexcept {
    return models_[static_cast<std::size_t>(body)];
  }
  const IdentifyConfig& config() const noexcept { return config_; }

 private:
  using Track = MotionTrack;
  using MarkerPoints = std::array<std::int16_t, kMaxMarkers>;

  Identifier(const IdentifyConfig& config, std::vector<TargetModel> models,
             double marker_diameter_mm);
  // Temporal path of one body (identifier_temporal.cpp): true when res(body) holds a
  // validated solution; gated_[body] tells whether the gated search decided it.
  bool temporal_match(int body, std::int64_t t_ns) noexcept;
  bool nearest_match(int body, const Iso3& T_pred, const std::array<double, kMaxMarkers>& gate_mm,
                     SearchResult& out) noexcept;
  bool gated_search(int body, SearchResult& out) noexcept;
  // Consistency test of a found solution and of its rival (false: rejected, counted).
  bool settle(int body, int min_m, SearchResult& r) noexcept;
  bool points_available(const MarkerPoints& pm, int k) const noexcept;
  void acquire_points(const MarkerPoints& pm, int k) noexcept;
  void release_points(const MarkerPoints& pm, int k) noexcept;
  void resolve_warm_conflicts() noexcept;
  void resolve_pending(std::int64_t t_ns) noexcept;
  void full_search(int body) noexcept;

  IdentifyConfig config_;
  std::vector<TargetModel> models_;
  double max_pair_mm_ = 0.0;
  MotionBounds motion_;
  FramePoints frame_;
  TargetSearch search_;
  ConsistencyGate gate_;
  std::vector<Track> tracks_;
  std::vector<SearchResult> results_;
  std::vector<std::uint8_t> state_;    // per body, per frame (see identifier.cpp)
  std::vector<std::uint8_t> gated_;    // per body, this frame: decided by the gated search
  std::vector<std::int16_t> pending_;  // bodies awaiting the conflict resolution
  int pending_count_ = 0;
  MarkerCandidates cand_;  // the gates' points of the body on the temporal path
  IdentifyCounters counters_;
  std::vector<std::string> warnings_;
  std::vector<AmbiguityFinding> ambiguities_;
};

}  // namespace mocap
