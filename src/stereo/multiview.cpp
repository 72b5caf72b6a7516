// Design: see multiview.h.
#include "stereo/multiview.h"

#include <algorithm>
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
    c.claim_views = false;
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
      claims_(static_cast<std::size_t>(config.max_hypotheses)),
      claim_margin_mm_(claims_.size() * rig.cameras.size()),
      claim_unfit_(claims_.size() * rig.cameras.size()),
      claim_of_(rig.cameras.size() * static_cast<std::size_t>(config.max_points_per_camera)),
      dup_head_(static_cast<std::size_t>(config.max_hypotheses)),
      dup_next_(static_cast<std::size_t>(config.max_hypotheses)),
      dup_tail_(static_cast<std::size_t>(config.max_hypotheses)) {}

double MultiViewMerger::unfit_gate_px(int c, const Vec3& X_world) const noexcept {
  const CameraModel& cam = cams_[static_cast<std::size_t>(c)];
  const double z = (cam.R_cam_world * X_world + cam.t_cam_world).z();
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
    const Vec3 Xc = cam.R_cam_world * h.X_world + cam.t_cam_world;
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
    if (!refine_gauss_newton(cams, obs, k, X, rms, kRefineIterations, kStepToleranceMm)) return;
    int worst = -1;
    double worst_d = config_.gate_px;
    for (int v = 0; v < k; ++v) {
      Vec2 q;
      const double d = project(*cams[v], X, q) ? (q - obs[v]).norm() : 1e300;
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
  for (int c = 0; c < camera_count(); ++c) {
    const int m = grids_[static_cast<std::size_t>(c)].build(px[c], n[c]);
    if (n[c] > m) counters_.blob_overflow += static_cast<std::uint64_t>(n[c] - m);
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
  same_index_.clear(count);
  const bool claims = config_.claim_views;
  if (claims) {
    claim_count_ = 0;
    std::fill(claim_of_.begin(), claim_of_.end(), -1);
  }
  int keys = 0;  // hypotheses in order_ (claimed ones follow their claim, dup lists)
  for (int i = 0; i < count; ++i) {
    Point3& h = hyp_[static_cast<std::size_t>(i)];
    dup_head_[static_cast<std::size_t>(i)] = -1;
    const int claim_hyp = claims ? take_claimed(i) : -1;
    if (claim_hyp < 0) {
      extend(i);
      extended_[static_cast<std::size_t>(i)] = h.blob_index;
      // The same point from another pair: the same blobs once extended.
      const int same = same_as_earlier(i);
      if (same >= 0) {
        h = hyp_[static_cast<std::size_t>(same)];  // refined already
        partial_views_[static_cast<std::size_t>(i)] =
            partial_views_[static_cast<std::size_t>(same)];
      } else {
        refine(i, px);
        if (claims) make_claim(i);
      }
    }
    views_[static_cast<std::size_t>(i)] = h.blob_index.count();
    if (claim_hyp >= 0) {  // after its claim in index order (the sort's last key)
      const auto j = static_cast<std::size_t>(claim_hyp);
      dup_next_[static_cast<std::size_t>(i)] = -1;
      if (dup_head_[j] < 0)
        dup_head_[j] = i;
      else
        dup_next_[static_cast<std::size_t>(dup_tail_[j])] = i;
      dup_tail_[j] = i;
      continue;
    }
    order_[static_cast<std::size_t>(keys++)] =
        AcceptKey{views_[static_cast<std::size_t>(i)], partial_views_[static_cast<std::size_t>(i)],
                  h.reproj_px, i};
  }
  // The keys sit side by side (not looked up in hyp_): the sort touches one small array.
  const auto by_acceptance = [](const AcceptKey& a, const AcceptKey& b) {
    if (a.views != b.views) return a.views > b.views;
    // Then the cameras that see part of the ball there: a ghost (two blobs of different
    // markers on one epipolar line) has no image at all in the other cameras.
    if (a.partial != b.partial) return a.partial > b.partial;
    return a.reproj_px != b.reproj_px ? a.reproj_px < b.reproj_px : a.index < b.index;
  };
  std::sort(order_.begin(), order_.begin() + keys, by_acceptance);
  if (keys < count && ties_a_claim(keys)) {
    // A claim's key ties another's exactly (exact duplicate blobs): its claimed copies
    // might interleave with that one; sort every hypothesis, as the reference does.
    for (int i = 0; i < count; ++i) {
      dup_head_[static_cast<std::size_t>(i)] = -1;
      order_[static_cast<std::size_t>(i)] = AcceptKey{
          views_[static_cast<std::size_t>(i)], partial_views_[static_cast<std::size_t>(i)],
          hyp_[static_cast<std::size_t>(i)].reproj_px, i};
    }
    keys = count;
    std::sort(order_.begin(), order_.begin() + keys, by_acceptance);
  }
  std::fill(taken_by_.begin(), taken_by_.end(), -1);
  for (int r = 0; r < keys; ++r) {
    const int i = order_[static_cast<std::size_t>(r)].index;
    const bool taken = accept(i, px, out, complete);
    int d = dup_head_[static_cast<std::size_t>(i)];
    if (d >= 0 && taken && owns_a_blob(out.size() - 1)) {
      // Its copies' blobs are a taken point's hypothesis's: each one is merged.
      for (; d >= 0; d = dup_next_[static_cast<std::size_t>(d)]) ++counters_.merged;
    }
    for (; d >= 0; d = dup_next_[static_cast<std::size_t>(d)]) accept(d, px, out, complete);
  }
  return complete;
}

}  // namespace mocap
