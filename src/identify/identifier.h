// Design: the per-frame rigid-body identification stage. Immutable models plus a
// preallocated workspace (Ceres/Pinocchio style): create() validates the configuration
// and the targets, precomputes the models, runs the ambiguity detection and sizes every
// buffer; identify() is noexcept and allocation-free.
// Per frame:
//  1. temporal path (bodies with a recent pose): predict the pose (constant pose or
//     constant velocity), match each predicted marker to the single available point in
//     its gate, refit (Umeyama), validate (every residual < t, m >= warm_min_markers,
//     every gate unique, no point shared with another body, speed limits); on failure the
//     body falls back to the full search.
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
//  4. a pose that moved faster than max_speed_mm_per_s / max_angular_speed_deg_per_s
//     since the body was last seen (the limits scale with that time) drops the body's
//     track (counted); the solution, a fresh full search of this frame that passed the
//     ambiguity and consistency tests, re-acquires ("boots") the body in the same frame.
//  The temporal path's gate scales with the time since the body was last seen.
#pragma once

#include <string>
#include <vector>

#include "core/expected.h"
#include "formats/targets_yaml.h"
#include "identify/ambiguity.h"
#include "identify/consistency.h"
#include "identify/frame_points.h"
#include "identify/identify_types.h"
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
  struct Track {
    bool valid = false;
    bool has_prev = false;
    Iso3 T_last = Iso3::Identity();
    std::int64_t t_last_ns = 0;
    Iso3 T_prev = Iso3::Identity();
    std::int64_t t_prev_ns = 0;
  };

  Identifier(const IdentifyConfig& config, std::vector<TargetModel> models,
             double marker_diameter_mm);
  Iso3 predict(const Track& track, std::int64_t t_ns) const noexcept;
  bool warm_match(int body, const Iso3& T_pred, SearchResult& out) noexcept;
  bool within_speed_limits(const Track& track, const Iso3& T, std::int64_t t_ns) const noexcept;
  using MarkerPoints = std::array<std::int16_t, kMaxMarkers>;
  bool points_available(const MarkerPoints& pm, int k) const noexcept;
  void acquire_points(const MarkerPoints& pm, int k) noexcept;
  bool conflicts(const SearchResult& a, int ka, const SearchResult& b, int kb) const noexcept;
  void full_search(int body) noexcept;

  IdentifyConfig config_;
  std::vector<TargetModel> models_;
  double max_pair_mm_ = 0.0;
  double warm_gate_mm_ = 0.0;  // this body's warm gate in this frame (age-scaled)
  FramePoints frame_;
  TargetSearch search_;
  ConsistencyGate gate_;
  std::vector<Track> tracks_;
  std::vector<SearchResult> results_;
  std::vector<std::uint8_t> state_;  // per body, per frame (see identifier.cpp)
  IdentifyCounters counters_;
  std::vector<std::string> warnings_;
  std::vector<AmbiguityFinding> ambiguities_;
};

}  // namespace mocap
