// Design: the paper's Eq. 1 search for one target in one frame (Section 2.1).
//  1. 2-matchings: every measured pair (i, j) whose distance D is within t of a model
//     pair distance d(a, b) (merge of the two sorted lists) gives the correspondences
//     (i->a, j->b) and (i->b, j->a) with discrepancy |D - d|; a bounded max-heap keeps
//     the best `best_pairs` (the paper's only heuristic).
//  2. From each 2-matching, in order of discrepancy, a depth-first, RANSAC-like
//     extension visits the remaining model markers: each is either matched to an
//     available point whose distance to every matched point agrees with the model within
//     t, or left unmatched. For m >= 3 the transform is fitted by Umeyama and every
//     residual must stay under t. Every such node is a candidate solution scored by
//     Eq. 1: sqrt(|r|^2 + m*floor^2) * base^(k-m) / m; the lowest score wins (ties: more m).
//  3. Runner-up pass (if ambiguity_ratio > 1): the same search again, now keeping the
//     best solution that contradicts the winner (a point on another marker or a marker
//     on another point, unless that point is within a ball's diameter of the winner's:
//     the same ball measured twice; or extra markers that cannot join the winner's: on
//     points a winner's point excludes, or with the union not rigidly consistent),
//     pruned at ambiguity_ratio * best score. The caller rejects a
//     winner whose rival is that close: an ambiguous frame gives no identity at all.
//  Gated mode (the temporal path, identification by continuity): each marker may only
//  take one of the points given for it (those within the gate around its predicted
//  position), for the seeds and the extension alike; winner and rival are then the best
//  and the best contradicting placement within the gates.
//  4. Pruning that never loses the optimum of the explored seeds: a branch stops when a
//     lower bound of any completion's score (|r| cannot shrink when points are added to a
//     least-squares fit) is not better than the best so far; a correspondence pair that
//     was an earlier seed is not taken again (every superset of it was already explored).
// Workspace sized at construction; run() is noexcept and allocation-free.
#pragma once

#include <vector>

#include "identify/frame_points.h"
#include "identify/rigid_fit.h"
#include "identify/target_model.h"

namespace mocap {

struct SearchResult {
  bool found = false;
  int m = 0;
  double score = 0.0;
  double sum_sq_mm2 = 0.0;
  double rms_mm = 0.0;
  Iso3 T_world_body = Iso3::Identity();
  std::array<std::int16_t, kMaxMarkers> point_of_marker{};
  // Best solution contradicting this one (runner-up pass), score +inf if none.
  double rival_score = 0.0;
  std::array<std::int16_t, kMaxMarkers> rival_point_of_marker{};
  bool unique(double ratio) const noexcept { return ratio <= 1.0 || rival_score >= ratio * score; }
};

// The points a marker may take in a gated search (ascending index, at most kMax each).
struct MarkerCandidates {
  static constexpr int kMax = 8;
  std::array<std::array<std::int16_t, kMax>, kMaxMarkers> point{};
  std::array<std::int8_t, kMaxMarkers> count{};
};

struct SearchStats {
  int seeds = 0;          // 2-matchings kept
  int seeds_dropped = 0;  // 2-matchings not kept (beyond best_pairs)
  int nodes = 0;          // extension steps visited
  bool node_limit_hit = false;
};

class TargetSearch {
 public:
  // same_ball_mm: the marker balls' diameter (0: unknown). Two points closer than that are
  // measurements of one ball (two balls cannot be closer), so a rival that puts a marker
  // on such a point instead of the winner's does not contradict it.
  explicit TargetSearch(const IdentifyConfig& config, double same_ball_mm = 0.0);

  // Searches `model` among the available points of `frame` (occupancy is restored on
  // return). Returns out.found. With `gated`, marker c only takes gated->point[c][..].
  bool run(const TargetModel& model, FramePoints& frame, SearchResult& out, SearchStats& stats,
           const MarkerCandidates* gated = nullptr) noexcept;

 private:
  struct Seed {
    double disc_mm;
    std::int16_t p0, p1;
    std::int8_t a0, a1;
  };
  void collect_seeds(const TargetModel& model, const FramePoints& frame,
                     SearchStats& stats) noexcept;
  void collect_gated_seeds(const TargetModel& model, const FramePoints& frame,
                           SearchStats& stats) noexcept;
  void push_seed(const Seed& s, SearchStats& stats) noexcept;
  void extend(int level, double sum_sq) noexcept;
  void run_pass() noexcept;
  void record(double score, const RigidFit& fit) noexcept;
  bool contradicts_best() noexcept;
  double score_of(int m, double sum_sq) const noexcept;
  // Whether some completion with m_now..m_max markers may score below limit (a lower
  // bound: |r| cannot shrink when points are added to a least-squares fit).
  bool may_beat(int m_now, int m_max, double sum_sq, double limit) const noexcept;
  bool was_seed(int c, int p, int a, int q) const noexcept;
  void mark_seed(int seed_index) noexcept;

  IdentifyConfig config_;
  double same_ball_sq_mm2_ = 0.0;
  std::vector<Seed> heap_;
  int heap_size_ = 0;
  // Processed seeds indexed by marker pair (a < b): head_[a][b] -> seed, next_[seed].
  std::array<std::array<std::int16_t, kMaxMarkers>, kMaxMarkers> head_{};
  std::vector<std::int16_t> next_;
  // Current search state.
  const TargetModel* model_ = nullptr;
  FramePoints* frame_ = nullptr;
  const MarkerCandidates* gated_ = nullptr;
  int m_ = 0;
  std::array<std::int8_t, kMaxMarkers> slot_marker_{};
  std::array<std::int16_t, kMaxMarkers> slot_point_{};
  std::array<std::int8_t, kMaxMarkers> order_{};
  int order_count_ = 0;
  FitPoints src_;
  FitPoints dst_;
  FitPoints union_src_;  // contradicts_best(): the best solution plus the node's extras
  FitPoints union_dst_;
  int nodes_ = 0;
  bool limit_hit_ = false;
  SearchResult* best_ = nullptr;
  bool rival_pass_ = false;
};

}  // namespace mocap
