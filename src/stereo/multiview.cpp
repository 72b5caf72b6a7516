// Design: see multiview.h.
#include "stereo/multiview.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdlib>
#include <string>
#include <utility>

#include "stereo/nview.h"

namespace mocap {
namespace {
// Gauss-Newton starts at the pair's optimal (niter2) point, close to the N-view optimum;
// 3 steps gave the same RMSE as 10 on the 4-camera ring of tests/stereo/test_multiview.cpp
// (0.1416 mm, MULTIVIEW_VERBOSE=1), and cut the merge's time (docs/performance.md).
constexpr int kRefineIterations = 3;
// A step below this ends the refinement: a thousandth of a marker's 3D noise (0.1 mm and
// more at these ranges), so stopping there moves no point measurably.
constexpr double kStepToleranceMm = 1e-4;
// Views of a point that settles its blobs (multiview.h, "Settled blobs").
constexpr int kSettleViews = 3;
}  // namespace

Expected<MultiViewMerger> MultiViewMerger::create(const Rig& rig, const MultiViewConfig& config) {
  const int n = static_cast<int>(rig.cameras.size());
  if (n < 2 || n > kMaxCameras)
    return Error{"multiview: " + std::to_string(n) + " cameras, expected 2.." +
                 std::to_string(kMaxCameras)};
  if (!(config.gate_px > 0.0)) return Error{"multiview: gate_px must be positive"};
  if (!(config.marker_radius_mm >= 0.0) || !std::isfinite(config.marker_radius_mm))
    return Error{"multiview: marker_radius_mm must be >= 0"};
  if (config.max_points_per_camera < 1 || config.max_hypotheses < 1)
    return Error{"multiview: max_points_per_camera and max_hypotheses must be positive"};
  if (!(config.grid_cell_px > 0.0) || !std::isfinite(config.grid_cell_px))
    return Error{"multiview: grid_cell_px must be a positive number"};
  std::vector<BlobGrid> grids;
  for (const CameraModel& cam : rig.cameras) {
    auto grid = BlobGrid::create(std::max(cam.width, 0), std::max(cam.height, 0),
                                 config.grid_cell_px, config.max_points_per_camera);
    if (!grid) return Error{"multiview: " + cam.name + ": " + grid.error().message};
    grids.push_back(std::move(grid).value());
  }
  auto same_index = BlobSetIndex::create(config.max_hypotheses);
  if (!same_index) return Error{"multiview: " + same_index.error().message};
  MultiViewConfig c = config;
  // Test-only switch (setup): run the reference in an unmodified binary (`mocap track`).
  if (const char* e = std::getenv("MOCAP_MULTIVIEW_REFERENCE"); e != nullptr && e[0] == '1')
    c.settle_blobs = false;
  return MultiViewMerger(rig, c, std::move(grids), std::move(same_index).value());
}

MultiViewMerger::MultiViewMerger(const Rig& rig, const MultiViewConfig& config,
                                 std::vector<BlobGrid> grids, BlobSetIndex same_index)
    : cams_(rig.cameras),
      config_(config),
      hyp_(static_cast<std::size_t>(config.max_hypotheses)),
      views_(static_cast<std::size_t>(config.max_hypotheses)),
      partial_views_(static_cast<std::size_t>(config.max_hypotheses)),
      extended_(static_cast<std::size_t>(config.max_hypotheses)),
      out_hyp_(static_cast<std::size_t>(config.max_hypotheses)),
      order_(static_cast<std::size_t>(config.max_hypotheses)),
      taken_by_(rig.cameras.size() * static_cast<std::size_t>(config.max_points_per_camera)),
      grids_(std::move(grids)),
      same_index_(std::move(same_index)),
      settled_by_(rig.cameras.size() * static_cast<std::size_t>(config.max_points_per_camera), -1) {
}

double MultiViewMerger::unfit_gate_px(int c, const Vec3& X_world) const noexcept {
  const CameraModel& cam = cams_[static_cast<std::size_t>(c)];
  const double z = to_camera(cam, X_world).z();
  if (!(z > 0.0)) return 0.0;
  return unfit_gate_at_depth_px(c, z);
}

// Adds every camera not yet used whose nearest blob lies within the gate of the
// projection (the nearest one only: two blobs within 2 px are one marker's split); a
// nearest blob beyond the gate but within the unfit gate is counted as an unfit view.
// The blobs are those of grids_[c] (the first max_points_per_camera of camera c).
void MultiViewMerger::extend(int i) noexcept {
  Point3& h = hyp_[static_cast<std::size_t>(i)];
  int& partial = partial_views_[static_cast<std::size_t>(i)];
  partial = 0;
  const bool indexed = config_.search == MergeSearch::kIndexed;
  for (int c = 0; c < camera_count(); ++c) {
    const BlobGrid& grid = grids_[static_cast<std::size_t>(c)];
    if (h.blob_index[c] >= 0 || grid.size() == 0) continue;  // no blob: nothing to find
    // project() and unfit_gate_px() from one camera-frame point (the same values).
    const CameraModel& cam = cams_[static_cast<std::size_t>(c)];
    const Vec3 Xc = to_camera(cam, h.X_world);
    if (!(Xc.z() > 1e-9)) continue;  // behind
    const Vec2 q = normalized_to_pixel(cam, Vec2(Xc.x() / Xc.z(), Xc.y() / Xc.z()));
    const double wide = std::max(config_.gate_px, unfit_gate_at_depth_px(c, Xc.z()));
    double best_d2 = 0.0;
    const int best = indexed ? grid.nearest(q, wide, best_d2) : grid.nearest_scan(q, wide, best_d2);
    if (best < 0) continue;
    if (best_d2 <= config_.gate_px * config_.gate_px) {
      h.blob_index[c] = static_cast<std::int16_t>(best);
      ++counters_.views_added;
    } else {
      ++counters_.unfit_views;
      ++partial;
    }
  }
}

// Gauss-Newton over the views; the worst view beyond the gate is dropped (while more
// than two remain) and the point refined again. A dropped view within the unfit gate is
// counted as an unfit view.
void MultiViewMerger::refine(int i, const Vec2* const* px) noexcept {
  Point3& h = hyp_[static_cast<std::size_t>(i)];
  for (;;) {
    const CameraModel* cams[kMaxCameras];
    Vec2 obs[kMaxCameras];
    int cam_of[kMaxCameras];
    int k = 0;
    for (int c = 0; c < camera_count(); ++c) {
      const int j = h.blob_index[c];
      if (j < 0) continue;
      cams[k] = &cams_[static_cast<std::size_t>(c)];
      obs[k] = px[c][j];
      cam_of[k++] = c;
    }
    if (k < 3) return;  // two views: the pair's optimal (niter2) point stands
    Vec3 X = h.X_world;
    double rms = 0.0;
    double r2[kMaxCameras];  // each view's squared residual at X (the RMS's evaluation)
    if (!refine_gauss_newton(cams, obs, k, X, rms, kRefineIterations, kStepToleranceMm, r2)) return;
    int worst = -1;
    double worst_d = config_.gate_px;
    for (int v = 0; v < k; ++v) {
      const double d = std::sqrt(r2[v]);
      if (d > worst_d) {
        worst_d = d;
        worst = v;
      }
    }
    if (worst < 0) {
      h.X_world = X;
      h.reproj_px = rms;
      return;
    }
    const int c = cam_of[worst];
    if (worst_d <= unfit_gate_px(c, X)) ++counters_.unfit_views;
    h.blob_index[c] = -1;
    ++counters_.views_dropped;
  }
}

int MultiViewMerger::same_as_earlier(int i) noexcept {
  const BlobRefs& key = extended_[static_cast<std::size_t>(i)];
  if (config_.search == MergeSearch::kIndexed) {
    const int same = same_index_.find_or_insert(extended_.data(), i);
    if (same != BlobSetIndex::kFull) return same;  // cannot fill: one entry per hypothesis
  }
  for (int k = 0; k < i; ++k)
    if (extended_[static_cast<std::size_t>(k)] == key) return k;
  return -1;
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
  if (!refine_gauss_newton(cams, obs, k, X, rms, 2 * kRefineIterations, kStepToleranceMm))
    return false;
  p.X_world = X;
  p.reproj_px = rms;
  return true;
}

bool MultiViewMerger::process(const Vec2* const* px, const int* n, const PointList* const* pairs,
                              int pair_count, PointList& out) noexcept {
  begin_frame(px, n);
  for (int p = 0; p < pair_count; ++p) add_pair(*pairs[p], px);
  return finish(px, out);
}

void MultiViewMerger::begin_frame(const Vec2* const* px, const int* n) noexcept {
  ++counters_.frames;
  complete_ = true;
  count_ = 0;
  if (camera_count() == 2) return;  // a pass-through: no grid, nothing settles
  long blobs = 0;
  for (int c = 0; c < camera_count(); ++c) {
    const int m = grids_[static_cast<std::size_t>(c)].build(px[c], n[c]);
    if (n[c] > m) counters_.blob_overflow += static_cast<std::uint64_t>(n[c] - m);
    blobs += m;
  }
  // The duplicate table sized for about one hypothesis per blob and other camera (a
  // frame with more falls back to linear comparisons: the same result, counted nowhere).
  same_index_.clear(static_cast<int>(
      std::min<long>(config_.max_hypotheses, blobs * std::max(1, camera_count() - 1))));
  std::fill(settled_by_.begin(), settled_by_.end(), -1);
}

// Steps 1-3 for hypothesis i: extension, the duplicate lookup, refinement; a point seen
// by three or more cameras settles its views.
void MultiViewMerger::merge_views(int i, const Vec2* const* px) noexcept {
  Point3& h = hyp_[static_cast<std::size_t>(i)];
  extend(i);
  extended_[static_cast<std::size_t>(i)] = h.blob_index;
  // The same point from another pair: the same blobs once extended.
  const int same = same_as_earlier(i);
  if (same >= 0) {
    h = hyp_[static_cast<std::size_t>(same)];  // refined already
    partial_views_[static_cast<std::size_t>(i)] = partial_views_[static_cast<std::size_t>(same)];
  } else {
    refine(i, px);
  }
  views_[static_cast<std::size_t>(i)] = h.blob_index.count();
  if (config_.settle_blobs && views_[static_cast<std::size_t>(i)] >= kSettleViews) settle(i);
}

void MultiViewMerger::settle(int i) noexcept {
  const BlobRefs& views = hyp_[static_cast<std::size_t>(i)].blob_index;
  const std::size_t per_cam = static_cast<std::size_t>(config_.max_points_per_camera);
  for (int c = 0; c < camera_count(); ++c) {
    const int j = views[c];
    if (j < 0 || j >= config_.max_points_per_camera) continue;
    int& slot = settled_by_[static_cast<std::size_t>(c) * per_cam + static_cast<std::size_t>(j)];
    if (slot < 0) slot = i;  // the first one keeps a blob
  }
}

// The candidates of one pair, in order (hypothesis indices run on across the pairs of the
// frame). A candidate of two blobs that EARLIER pairs settled (hypothesis index before
// this pair's first) is none: the pairwise stage given SettledBlobs never makes it.
// Every candidate of a pair's list uses the pair's two cameras, so they are looked up
// once, in the first candidate; a candidate with other views (none of the pairwise
// stage's) is a hypothesis without the settled test.
void MultiViewMerger::add_pair(const PointList& pair, const Vec2* const* px) noexcept {
  const int first = count_;
  const std::size_t per_cam = static_cast<std::size_t>(config_.max_points_per_camera);
  const bool pass_through = camera_count() == 2;  // one pair: its candidates are the answer
  // The pair's two cameras, from its first candidate, and their mask.
  int cam[2] = {-1, -1};
  CameraMask pair_mask = 0;
  if (config_.settle_blobs && !pass_through && !pair.empty() &&
      pair.begin()->blob_index.count() == 2) {
    pair_mask = pair.begin()->blob_index.mask();
    cam[0] = std::countr_zero(pair_mask);
    cam[1] = std::countr_zero(pair_mask & (pair_mask - 1));
  }
  // Per view of the pair: the blob's settling hypothesis from an earlier pair, -1: none.
  const auto settled_earlier = [&](int e, const Point3& c) noexcept {
    const int j = c.blob_index[cam[e]];
    const int by =
        j < config_.max_points_per_camera
            ? settled_by_[static_cast<std::size_t>(cam[e]) * per_cam + static_cast<std::size_t>(j)]
            : -1;
    return by < first ? by : -1;  // settled by earlier pairs only
  };
  for (const Point3& c : pair) {
    if (pair_mask != 0 && c.blob_index.mask() == pair_mask) {
      const int settled[2] = {settled_earlier(0, c), settled_earlier(1, c)};
      if (settled_pair(settled[0], settled[1])) {
        ++counters_.settled;
        continue;
      }
    }
    ++counters_.hypotheses;
    if (count_ >= config_.max_hypotheses) {
      ++counters_.hypothesis_overflow;
      complete_ = false;
      continue;
    }
    const int i = count_++;
    hyp_[static_cast<std::size_t>(i)] = c;
    if (pass_through) continue;
    merge_views(i, px);
    order_[static_cast<std::size_t>(i)] =
        AcceptKey{views_[static_cast<std::size_t>(i)], partial_views_[static_cast<std::size_t>(i)],
                  hyp_[static_cast<std::size_t>(i)].reproj_px, i};
  }
}

bool MultiViewMerger::finish(const Vec2* const* px, PointList& out) noexcept {
  out.clear();
  bool complete = complete_;
  if (camera_count() == 2) {
    for (int i = 0; i < count_; ++i) {
      const Point3& c = hyp_[static_cast<std::size_t>(i)];
      if (!out.push_back(c)) {
        ++counters_.point_overflow;
        complete = false;
        continue;
      }
      ++counters_.points;
      if (c.ambiguous) ++counters_.ambiguous;
    }
    return complete;
  }
  // The keys sit side by side (not looked up in hyp_): the sort touches one small array.
  std::sort(order_.begin(), order_.begin() + count_, [](const AcceptKey& a, const AcceptKey& b) {
    if (a.views != b.views) return a.views > b.views;
    // Then the cameras that see part of the ball there: a ghost (two blobs of different
    // markers on one epipolar line) has no image at all in the other cameras.
    if (a.partial != b.partial) return a.partial > b.partial;
    return a.reproj_px != b.reproj_px ? a.reproj_px < b.reproj_px : a.index < b.index;
  });
  std::fill(taken_by_.begin(), taken_by_.end(), -1);
  for (int r = 0; r < count_; ++r)
    accept(order_[static_cast<std::size_t>(r)].index, px, out, complete);
  return complete;
}

}  // namespace mocap
