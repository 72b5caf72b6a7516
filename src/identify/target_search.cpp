// Design: see target_search.h for the algorithm. Implementation notes: the seed queue is
// a std::push_heap/pop_heap max-heap over a preallocated array (worst kept on top), so
// keeping the best N of M candidates costs O(M log N) without allocation; the extension
// is a recursion of depth <= k - 2 over member state (slots of matched correspondences).
#include "identify/target_search.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace mocap {
namespace {
constexpr auto kSeedLess = [](const auto& x, const auto& y) { return x.disc_mm < y.disc_mm; };
}  // namespace

TargetSearch::TargetSearch(const IdentifyConfig& config, double same_ball_mm)
    : config_(config),
      same_ball_sq_mm2_(same_ball_mm > 0.0 ? same_ball_mm * same_ball_mm : 0.0),
      heap_(static_cast<std::size_t>(config.best_pairs)),
      next_(static_cast<std::size_t>(config.best_pairs), -1),
      src_(3, kMaxMarkers),
      dst_(3, kMaxMarkers),
      union_src_(3, kMaxMarkers),
      union_dst_(3, kMaxMarkers) {}

void TargetSearch::push_seed(const Seed& s, SearchStats& stats) noexcept {
  const auto cap = static_cast<int>(heap_.size());
  if (heap_size_ < cap) {
    heap_[static_cast<std::size_t>(heap_size_++)] = s;
    std::push_heap(heap_.begin(), heap_.begin() + heap_size_, kSeedLess);
    return;
  }
  ++stats.seeds_dropped;
  if (!(s.disc_mm < heap_.front().disc_mm)) return;
  std::pop_heap(heap_.begin(), heap_.begin() + heap_size_, kSeedLess);
  heap_[static_cast<std::size_t>(heap_size_ - 1)] = s;
  std::push_heap(heap_.begin(), heap_.begin() + heap_size_, kSeedLess);
}

void TargetSearch::collect_seeds(const TargetModel& model, const FramePoints& frame,
                                 SearchStats& stats) noexcept {
  heap_size_ = 0;
  const double t = config_.t_mm;
  const PointPair* pp = frame.pairs();
  const int np = frame.pair_count();
  const auto cap = static_cast<int>(heap_.size());
  int lo = 0;  // first measured pair with D > d - t (monotone: model pairs are sorted)
  for (const ModelPair& mp : model.pairs_sorted) {
    while (lo < np && pp[lo].d_mm <= mp.d_mm - t) ++lo;
    for (int q = lo; q < np && pp[q].d_mm < mp.d_mm + t; ++q) {
      const PointPair& p = pp[q];
      const double disc = std::abs(p.d_mm - mp.d_mm);
      // A full heap keeps only better ones: skip before the (costlier) availability test.
      if (heap_size_ == cap && !(disc < heap_.front().disc_mm)) {
        stats.seeds_dropped += 2;
        continue;
      }
      if (!frame.available(p.i) || !frame.available(p.j)) continue;
      push_seed(Seed{disc, p.i, p.j, mp.a, mp.b}, stats);
      push_seed(Seed{disc, p.j, p.i, mp.a, mp.b}, stats);
    }
  }
  std::sort_heap(heap_.begin(), heap_.begin() + heap_size_, kSeedLess);
  stats.seeds = heap_size_;
}

void TargetSearch::collect_gated_seeds(const TargetModel& model, const FramePoints& frame,
                                       SearchStats& stats) noexcept {
  heap_size_ = 0;
  const double t = config_.t_mm;
  const MarkerCandidates& g = *gated_;
  for (const ModelPair& mp : model.pairs_sorted) {
    const auto a = static_cast<std::size_t>(mp.a), b = static_cast<std::size_t>(mp.b);
    for (int u = 0; u < g.count[a]; ++u) {
      const int p = g.point[a][static_cast<std::size_t>(u)];
      for (int v = 0; v < g.count[b]; ++v) {
        const int q = g.point[b][static_cast<std::size_t>(v)];
        if (p == q || !frame.available(p) || !frame.available(q) || frame.exclusive(p, q)) continue;
        const double disc = std::abs((frame.X(p) - frame.X(q)).norm() - mp.d_mm);
        if (disc < t)
          push_seed(
              Seed{disc, static_cast<std::int16_t>(p), static_cast<std::int16_t>(q), mp.a, mp.b},
              stats);
      }
    }
  }
  std::sort_heap(heap_.begin(), heap_.begin() + heap_size_, kSeedLess);
  stats.seeds = heap_size_;
}

double TargetSearch::score_of(int m, double sum_sq) const noexcept {
  const double floor2 = config_.residual_floor_mm * config_.residual_floor_mm;
  return std::sqrt(sum_sq + m * floor2) * model_->score_factor[static_cast<std::size_t>(m)];
}

bool TargetSearch::may_beat(int m_now, int m_max, double sum_sq, double limit) const noexcept {
  // Whether the lowest of these scores is below limit: the first one that is settles it
  // (the most markers first, usually the lowest score).
  for (int m = m_max; m >= std::max(m_now, config_.min_markers); --m)
    if (score_of(m, sum_sq) < limit) return true;
  return false;
}

bool TargetSearch::was_seed(int c, int p, int a, int q) const noexcept {
  // Correspondences (c->p) and (a->q): was this pair an earlier, fully explored seed?
  if (c > a) {
    std::swap(c, a);
    std::swap(p, q);
  }
  for (int s = head_[static_cast<std::size_t>(c)][static_cast<std::size_t>(a)]; s >= 0;
       s = next_[static_cast<std::size_t>(s)]) {
    const Seed& sd = heap_[static_cast<std::size_t>(s)];
    // Stored seeds have a0 < a1 (model pairs are stored with a < b).
    if (sd.p0 == p && sd.p1 == q) return true;
  }
  return false;
}

void TargetSearch::mark_seed(int seed_index) noexcept {
  const Seed& sd = heap_[static_cast<std::size_t>(seed_index)];
  auto& h = head_[static_cast<std::size_t>(sd.a0)][static_cast<std::size_t>(sd.a1)];
  next_[static_cast<std::size_t>(seed_index)] = h;
  h = static_cast<std::int16_t>(seed_index);
}

void TargetSearch::extend(int level, double sum_sq) noexcept {
  if (limit_hit_) return;
  if (++nodes_ > config_.max_search_nodes) {
    limit_hit_ = true;
    return;
  }
  if (level >= order_count_) return;
  const int m_max = m_ + (order_count_ - level);
  if (m_max < config_.min_markers) return;
  if (rival_pass_) {
    const double limit = std::min(config_.ambiguity_ratio * best_->score, best_->rival_score);
    if (!may_beat(m_, m_max, sum_sq, limit)) return;
  } else if (best_->found && !may_beat(m_, m_max, sum_sq, best_->score)) {
    return;
  }

  const TargetModel& model = *model_;
  FramePoints& frame = *frame_;
  const double t = config_.t_mm;
  const double t2 = t * t;
  const int c = order_[static_cast<std::size_t>(level)];
  const auto cs = static_cast<std::size_t>(c);
  const Vec3& X0 = frame.X(slot_point_[0]);
  const double d0 = model.dist_mm[cs][static_cast<std::size_t>(slot_marker_[0])];
  const double lo2 = d0 > t ? (d0 - t) * (d0 - t) : 0.0;
  const double hi2 = (d0 + t) * (d0 + t);
  // Candidates: the marker's gate (gated mode), else the neighbours of the first slot's
  // point (every point closer than the longest pair + t; the others fail q2 < hi2),
  // nearest first: the band lo2 < q2 < hi2 starts where a bisection puts it and ends at
  // the first point beyond it (the same points as testing all, in another order).
  const bool gated = gated_ != nullptr;
  const std::int16_t* cand = gated ? gated_->point[cs].data() : frame.neighbours(slot_point_[0]);
  const int nc = gated ? gated_->count[cs] : frame.neighbour_count(slot_point_[0]);
  int first = 0;
  if (!gated) {
    for (int hi = nc; first < hi;) {
      const int mid = first + (hi - first) / 2;
      if ((frame.X(cand[mid]) - X0).squaredNorm() <= lo2)
        first = mid + 1;
      else
        hi = mid;
    }
  }
  for (int e = first; e < nc; ++e) {
    const int p = cand[e];
    const double q2 = (frame.X(p) - X0).squaredNorm();
    if (!gated && q2 >= hi2) break;
    if (q2 <= lo2 || q2 >= hi2 || !frame.available(p)) continue;
    bool ok = true;
    for (int s = 1; s < m_ && ok; ++s) {
      const double d = (frame.X(p) - frame.X(slot_point_[static_cast<std::size_t>(s)])).norm();
      ok = std::abs(d - model.dist_mm[cs][static_cast<std::size_t>(
                            slot_marker_[static_cast<std::size_t>(s)])]) < t;
    }
    for (int s = 0; s < m_ && ok; ++s)
      ok = !was_seed(c, p, slot_marker_[static_cast<std::size_t>(s)],
                     slot_point_[static_cast<std::size_t>(s)]);
    if (!ok) continue;
    // Take the correspondence c -> p.
    const auto ms = static_cast<std::size_t>(m_);
    slot_marker_[ms] = static_cast<std::int8_t>(c);
    slot_point_[ms] = static_cast<std::int16_t>(p);
    src_.col(m_) = model.M_body[cs];
    dst_.col(m_) = frame.X(p);
    ++m_;
    const RigidFit fit = fit_rigid(src_, dst_, m_);
    if (fit.max_sq_mm2 < t2) {
      if (m_ >= config_.min_markers) record(score_of(m_, fit.sum_sq_mm2), fit);
      frame.acquire(p);
      extend(level + 1, fit.sum_sq_mm2);
      frame.release(p);
    }
    --m_;
    if (limit_hit_) return;
  }
  // Leave marker c unmatched.
  extend(level + 1, sum_sq);
}

void TargetSearch::record(double score, const RigidFit& fit) noexcept {
  SearchResult& b = *best_;
  if (rival_pass_) {
    if (score < b.rival_score && contradicts_best()) {
      b.rival_score = score;
      b.rival_point_of_marker.fill(-1);
      for (int s = 0; s < m_; ++s)
        b.rival_point_of_marker[static_cast<std::size_t>(
            slot_marker_[static_cast<std::size_t>(s)])] = slot_point_[static_cast<std::size_t>(s)];
    }
    return;
  }
  if (b.found && !(score < b.score || (score == b.score && m_ > b.m))) return;
  b.found = true;
  b.m = m_;
  b.score = score;
  b.sum_sq_mm2 = fit.sum_sq_mm2;
  b.T_world_body = fit.T_dst_src;
  b.point_of_marker.fill(-1);
  for (int s = 0; s < m_; ++s)
    b.point_of_marker[static_cast<std::size_t>(slot_marker_[static_cast<std::size_t>(s)])] =
        slot_point_[static_cast<std::size_t>(s)];
}

// The current node contradicts the best solution when it puts a marker on another point
// than the best does, or a point on another marker: the two then tell different
// identities. A marker on a point within a ball's diameter of the best's point for it is
// the same identity: one ball measured twice (e.g. whole, and partly hidden through
// another camera pair). Solutions that agree wherever both assign (a subset, or two that
// complete each other) tell one identity only when together they are one solution: the
// node's extra markers on points that no best point excludes (shared blobs), and the
// union rigidly consistent (every residual under t). Otherwise they contradict too: e.g.
// a stray where the best puts a hidden marker, and the true point of another marker the
// best left out, each consistent alone, never both.
bool TargetSearch::contradicts_best() noexcept {
  const auto& best = best_->point_of_marker;
  const int k = model_->k;
  bool adds = false;
  for (int s = 0; s < m_; ++s) {
    const int c = slot_marker_[static_cast<std::size_t>(s)];
    const int sp = slot_point_[static_cast<std::size_t>(s)];
    const int bp = best[static_cast<std::size_t>(c)];
    if (bp == sp) continue;
    // The marker on another point (not the same ball).
    if (bp >= 0 && (frame_->X(bp) - frame_->X(sp)).squaredNorm() >= same_ball_sq_mm2_) return true;
    for (int a = 0; a < k; ++a)  // the point on another marker
      if (a != c && best[static_cast<std::size_t>(a)] == sp) return true;
    adds = adds || bp < 0;
  }
  if (!adds) return false;  // a subset of the best (up to the same balls)
  // The union: the best's correspondences plus the node's extra ones.
  int u = 0;
  for (int a = 0; a < k; ++a) {
    const int bp = best[static_cast<std::size_t>(a)];
    if (bp < 0) continue;
    union_src_.col(u) = model_->M_body[static_cast<std::size_t>(a)];
    union_dst_.col(u) = frame_->X(bp);
    ++u;
  }
  for (int s = 0; s < m_; ++s) {
    const int c = slot_marker_[static_cast<std::size_t>(s)];
    const int sp = slot_point_[static_cast<std::size_t>(s)];
    if (best[static_cast<std::size_t>(c)] >= 0) continue;
    for (int a = 0; a < k; ++a) {
      const int bp = best[static_cast<std::size_t>(a)];
      if (bp >= 0 && frame_->exclusive(bp, sp)) return true;
    }
    union_src_.col(u) = model_->M_body[static_cast<std::size_t>(c)];
    union_dst_.col(u) = frame_->X(sp);
    ++u;
  }
  const RigidFit fit = fit_rigid(union_src_, union_dst_, u);
  return !(fit.max_sq_mm2 < config_.t_mm * config_.t_mm);
}

void TargetSearch::run_pass() noexcept {
  const TargetModel& model = *model_;
  FramePoints& frame = *frame_;
  for (auto& row : head_) row.fill(-1);
  for (int s = 0; s < heap_size_ && !limit_hit_; ++s) {
    const Seed& sd = heap_[static_cast<std::size_t>(s)];
    m_ = 2;
    slot_marker_[0] = sd.a0;
    slot_point_[0] = sd.p0;
    slot_marker_[1] = sd.a1;
    slot_point_[1] = sd.p1;
    src_.col(0) = model.M_body[static_cast<std::size_t>(sd.a0)];
    dst_.col(0) = frame.X(sd.p0);
    src_.col(1) = model.M_body[static_cast<std::size_t>(sd.a1)];
    dst_.col(1) = frame.X(sd.p1);
    order_count_ = 0;
    for (int a = 0; a < model.k; ++a) {
      if (a != sd.a0 && a != sd.a1)
        order_[static_cast<std::size_t>(order_count_++)] = static_cast<std::int8_t>(a);
    }
    frame.acquire(sd.p0);
    frame.acquire(sd.p1);
    // Two-point least squares: each point is off by half the discrepancy.
    extend(0, 0.5 * sd.disc_mm * sd.disc_mm);
    frame.release(sd.p1);
    frame.release(sd.p0);
    mark_seed(s);
  }
}

bool TargetSearch::run(const TargetModel& model, FramePoints& frame, SearchResult& out,
                       SearchStats& stats, const MarkerCandidates* gated) noexcept {
  out = SearchResult{};
  out.point_of_marker.fill(-1);
  stats = SearchStats{};
  model_ = &model;
  frame_ = &frame;
  gated_ = gated;
  best_ = &out;
  nodes_ = 0;
  limit_hit_ = false;
  if (gated != nullptr) {
    collect_gated_seeds(model, frame, stats);
  } else {
    frame.prepare_pairs();
    collect_seeds(model, frame, stats);
  }
  rival_pass_ = false;
  run_pass();
  out.rival_score = std::numeric_limits<double>::infinity();
  out.rival_point_of_marker.fill(-1);
  if (out.found && config_.ambiguity_ratio > 1.0) {
    rival_pass_ = true;
    run_pass();
  }
  stats.nodes = nodes_;
  stats.node_limit_hit = limit_hit_;
  if (out.found) out.rms_mm = std::sqrt(out.sum_sq_mm2 / out.m);
  return out.found;
}

}  // namespace mocap
