// Design: see multiview.h.
#include "stereo/multiview.h"

#include <algorithm>
#include <string>

#include "stereo/nview.h"

namespace mocap {
namespace {
// Gauss-Newton starts at the pair's optimal (niter2) point, close to the N-view optimum;
// 3 steps gave the same RMSE as 10 on the 4-camera ring of tests/stereo/test_multiview.cpp
// (0.1416 mm, MULTIVIEW_VERBOSE=1), and cut the merge's time (docs/performance.md).
constexpr int kRefineIterations = 3;
}  // namespace

Expected<MultiViewMerger> MultiViewMerger::create(const Rig& rig, const MultiViewConfig& config) {
  const int n = static_cast<int>(rig.cameras.size());
  if (n < 2 || n > kMaxCameras)
    return Error{"multiview: " + std::to_string(n) + " cameras, expected 2.." +
                 std::to_string(kMaxCameras)};
  if (!(config.gate_px > 0.0)) return Error{"multiview: gate_px must be positive"};
  if (config.max_points_per_camera < 1 || config.max_hypotheses < 1)
    return Error{"multiview: max_points_per_camera and max_hypotheses must be positive"};
  return MultiViewMerger(rig, config);
}

MultiViewMerger::MultiViewMerger(const Rig& rig, const MultiViewConfig& config)
    : cams_(rig.cameras),
      config_(config),
      hyp_(static_cast<std::size_t>(config.max_hypotheses)),
      views_(static_cast<std::size_t>(config.max_hypotheses)),
      extended_(static_cast<std::size_t>(config.max_hypotheses)),
      order_(static_cast<std::size_t>(config.max_hypotheses)),
      taken_by_(rig.cameras.size() * static_cast<std::size_t>(config.max_points_per_camera)) {}

// Adds every camera not yet used whose nearest blob lies within the gate of the
// projection (the nearest one only: two blobs within 2 px are one marker's split).
void MultiViewMerger::extend(Point3& h, const Vec2* const* px, const int* n) noexcept {
  for (int c = 0; c < camera_count(); ++c) {
    if (h.blob_index[static_cast<std::size_t>(c)] >= 0) continue;
    Vec2 q;
    if (!project(cams_[static_cast<std::size_t>(c)], h.X_world, q)) continue;  // behind
    const int m = std::min(n[c], config_.max_points_per_camera);
    int best = -1;
    double best_d2 = config_.gate_px * config_.gate_px;
    for (int j = 0; j < m; ++j) {
      const double d2 = (px[c][j] - q).squaredNorm();
      if (d2 <= best_d2) {
        best_d2 = d2;
        best = j;
      }
    }
    if (best >= 0) {
      h.blob_index[static_cast<std::size_t>(c)] = static_cast<std::int16_t>(best);
      ++counters_.views_added;
    }
  }
}

// Gauss-Newton over the views; the worst view beyond the gate is dropped (while more
// than two remain) and the point refined again.
void MultiViewMerger::refine(Point3& h, const Vec2* const* px) noexcept {
  for (;;) {
    const CameraModel* cams[kMaxCameras];
    Vec2 obs[kMaxCameras];
    int cam_of[kMaxCameras];
    int k = 0;
    for (int c = 0; c < camera_count(); ++c) {
      const int j = h.blob_index[static_cast<std::size_t>(c)];
      if (j < 0) continue;
      cams[k] = &cams_[static_cast<std::size_t>(c)];
      obs[k] = px[c][j];
      cam_of[k++] = c;
    }
    if (k < 3) return;  // two views: the pair's optimal (niter2) point stands
    Vec3 X = h.X_world;
    double rms = 0.0;
    if (!refine_gauss_newton(cams, obs, k, X, rms, kRefineIterations)) return;
    int worst = -1;
    double worst_d = config_.gate_px;
    for (int i = 0; i < k; ++i) {
      Vec2 q;
      const double d = project(*cams[i], X, q) ? (q - obs[i]).norm() : 1e300;
      if (d > worst_d) {
        worst_d = d;
        worst = i;
      }
    }
    if (worst < 0) {
      h.X_world = X;
      h.reproj_px = rms;
      return;
    }
    h.blob_index[static_cast<std::size_t>(cam_of[worst])] = -1;
    ++counters_.views_dropped;
  }
}

bool MultiViewMerger::refit(Point3& p, const Vec2* const* px) const noexcept {
  const CameraModel* cams[kMaxCameras];
  Vec2 obs[kMaxCameras];
  int k = 0;
  for (int c = 0; c < camera_count(); ++c) {
    const int j = p.blob_index[c];
    if (j < 0) continue;
    cams[k] = &cams_[static_cast<std::size_t>(c)];
    obs[k++] = px[c][j];
  }
  if (k < 2) return false;
  Vec3 X = p.X_world;
  double rms = 0.0;
  // From a point the dropped view pulled by at most the gate: a few steps converge.
  if (!refine_gauss_newton(cams, obs, k, X, rms, 2 * kRefineIterations)) return false;
  p.X_world = X;
  p.reproj_px = rms;
  return true;
}

bool MultiViewMerger::process(const Vec2* const* px, const int* n, const PointList* const* pairs,
                              int pair_count, PointList& out) noexcept {
  ++counters_.frames;
  out.clear();
  bool complete = true;
  if (camera_count() == 2) {  // one pair: its candidates are the answer
    for (int p = 0; p < pair_count; ++p) {
      for (const Point3& c : *pairs[p]) {
        ++counters_.hypotheses;
        if (!out.push_back(c)) {
          ++counters_.point_overflow;
          complete = false;
          continue;
        }
        ++counters_.points;
        if (c.ambiguous) ++counters_.ambiguous;
      }
    }
    return complete;
  }
  int count = 0;
  for (int p = 0; p < pair_count; ++p) {
    for (const Point3& c : *pairs[p]) {
      ++counters_.hypotheses;
      if (count >= config_.max_hypotheses) {
        ++counters_.hypothesis_overflow;
        complete = false;
        continue;
      }
      hyp_[static_cast<std::size_t>(count++)] = c;
    }
  }
  for (int i = 0; i < count; ++i) {
    Point3& h = hyp_[static_cast<std::size_t>(i)];
    extend(h, px, n);
    extended_[static_cast<std::size_t>(i)] = h.blob_index;
    int same = -1;  // the same point from another pair: the same blobs once extended
    for (int k = 0; k < i && same < 0; ++k)
      if (extended_[static_cast<std::size_t>(k)] == h.blob_index) same = k;
    if (same >= 0)
      h = hyp_[static_cast<std::size_t>(same)];  // refined already
    else
      refine(h, px);
    views_[static_cast<std::size_t>(i)] = h.blob_index.count();
    order_[static_cast<std::size_t>(i)] = i;
  }
  std::sort(order_.begin(), order_.begin() + count, [&](int a, int b) {
    const int va = views_[static_cast<std::size_t>(a)], vb = views_[static_cast<std::size_t>(b)];
    if (va != vb) return va > vb;
    const double ra = hyp_[static_cast<std::size_t>(a)].reproj_px;
    const double rb = hyp_[static_cast<std::size_t>(b)].reproj_px;
    return ra != rb ? ra < rb : a < b;
  });
  const std::size_t per_cam = static_cast<std::size_t>(config_.max_points_per_camera);
  std::fill(taken_by_.begin(), taken_by_.end(), -1);
  for (int r = 0; r < count; ++r) {
    const int i = order_[static_cast<std::size_t>(r)];
    Point3 h = hyp_[static_cast<std::size_t>(i)];
    const int views = views_[static_cast<std::size_t>(i)];
    int owner = -1;  // a taken point using one of h's blobs
    bool all_same_owner = true, any_free = false, richer_owner = false;
    for (int c = 0; c < camera_count(); ++c) {
      const int j = h.blob_index[static_cast<std::size_t>(c)];
      if (j < 0) continue;
      const int o =
          j < config_.max_points_per_camera
              ? taken_by_[static_cast<std::size_t>(c) * per_cam + static_cast<std::size_t>(j)]
              : -1;
      if (o < 0) {
        any_free = true;
        all_same_owner = false;
        continue;
      }
      if (owner >= 0 && o != owner) all_same_owner = false;
      owner = o;
      richer_owner = richer_owner || out[o].blob_index.count() > views;
    }
    if (owner >= 0 && all_same_owner && !any_free) {
      ++counters_.merged;  // the same blobs: the same point from another pair
      continue;
    }
    if (richer_owner) {
      ++counters_.ghosts_rejected;  // a blob of a point that more cameras confirm
      continue;
    }
    h.ambiguous = owner >= 0;
    h.reported = !h.ambiguous;
    if (out.size() >= out.capacity()) {
      ++counters_.point_overflow;
      complete = false;
      continue;
    }
    const int index = out.size();
    for (int c = 0; c < camera_count(); ++c) {
      const int j = h.blob_index[static_cast<std::size_t>(c)];
      if (j < 0 || j >= config_.max_points_per_camera) continue;
      int& slot = taken_by_[static_cast<std::size_t>(c) * per_cam + static_cast<std::size_t>(j)];
      if (slot >= 0 && !out[slot].ambiguous) {
        out[slot].ambiguous = true;  // an equal rival: both go to identification
        out[slot].reported = false;
        ++counters_.ambiguous;
      }
      if (slot < 0) slot = index;
    }
    if (h.ambiguous) ++counters_.ambiguous;
    out.push_back(h);
    ++counters_.points;
  }
  return complete;
}

}  // namespace mocap
