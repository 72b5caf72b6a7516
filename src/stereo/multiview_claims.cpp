// Design: the N-view merge's claims (multiview.h): the first hypothesis of a blob set with
// three or more views claims its blobs; a later pair made of two of them, whose point lies
// within every other camera's margin of the claim's point, is given the claim's result
// without extension. The margin makes that result the reference's exactly:
//  - a camera where the claim has view v: v stays the nearest blob and within the gate
//    while the projection moves less than min(gate - d1, (d2 - d1) / 2) px (d1: v's
//    distance, d2: the runner-up's; the grid's nearest_two());
//  - a camera without a view: no blob enters the gate, and none crosses the unfit gate
//    (which decides the unfit_views counter), while it moves less than
//    min(d1 - gate, |d1 - unfit gate|) px, less the unfit gate's own change with the
//    depth (below 2 % of the ball's image radius within the distance cap);
//  - a camera that sees the point behind it: it stays behind within half its depth.
// Pixels become millimetres through the Frobenius norm of the projection's Jacobian at
// the claim's point (>= its spectral norm), halved for the Jacobian's change within the
// cap of 0.2 % of the depth, so a move of the margin changes the projection less than the
// pixel margin. The later pair's extension would then find the claim's extended blob set,
// and the duplicate lookup would return the claim's hypothesis (the first of that set):
// the same hypothesis, partial views and counters (views_added, unfit_views) follow.
// A claim's margins are computed per camera when a later pair first needs them (a pair
// needs every camera but its two): claims no pair consults cost nothing.
// Everything else takes the full treatment. In the acceptance the claimed copies follow
// their claim (the reference's sort puts them there: the same key but the index) unless
// a run of exactly tied keys mixes blob sets (ties_a_claim: then every key is sorted).
// noexcept, no allocation.
#include <algorithm>
#include <cmath>
#include <limits>

#include "stereo/multiview.h"

namespace mocap {
namespace {
constexpr double kJacobianSafety = 2.0;  // the Jacobian's change within the cap
constexpr double kDepthCap = 0.002;      // the margin's bound, as a fraction of the depth
constexpr double kRoundingPx = 1e-6;     // far above the rounding of the pixel distances
}  // namespace

double MultiViewMerger::claim_margin_mm(int c, int v, const Vec3& X, int& unfit) const noexcept {
  const BlobGrid& grid = grids_[static_cast<std::size_t>(c)];
  if (grid.size() == 0) return v < 0 ? std::numeric_limits<double>::infinity() : 0.0;
  const CameraModel& cam = cams_[static_cast<std::size_t>(c)];
  const double z = (cam.R_cam_world * X + cam.t_cam_world).z();
  if (!(z > 1e-9)) return v < 0 && z < 0.0 ? 0.5 * -z : 0.0;  // behind: extension skips it
  Vec2 q;
  double J[6];
  if (!project_jacobian(cam, X, q, J)) return 0.0;
  double L2 = 0.0;  // the Jacobian's Frobenius norm, squared
  for (const double j : J) L2 += j * j;
  const double L = std::sqrt(L2);
  if (!(L > 0.0) || !std::isfinite(L)) return 0.0;
  const double gate = config_.gate_px;
  const double wide = std::max(gate, unfit_gate_px(c, X));
  const double radius = wide + 2.0 * gate;
  double d1_sq = 0.0, d2_sq = 0.0;
  const int best = grid.nearest_two(q, radius, d1_sq, d2_sq);
  const double d1 = best >= 0 ? std::sqrt(d1_sq) : radius;
  double m = 0.0;
  if (v >= 0) {
    if (best != v) return 0.0;
    m = std::min(gate - d1, 0.5 * (std::sqrt(d2_sq) - d1));
  } else {
    m = d1 - gate;
    if (d1 <= wide) {
      ++unfit;
      m = std::min(m, wide - d1);
    } else {
      m = std::min(m, d1 - wide);
    }
    m -= 0.02 * (wide - gate);  // the unfit gate moves with the depth
  }
  m -= kRoundingPx;
  if (!(m > 0.0)) return 0.0;
  return std::min(m / (kJacobianSafety * L), kDepthCap * z);
}

void MultiViewMerger::make_claim(int i) noexcept {
  const BlobRefs& set = extended_[static_cast<std::size_t>(i)];
  if (set.count() < 3 || claim_count_ >= static_cast<int>(claims_.size())) return;
  Claim& claim = claims_[static_cast<std::size_t>(claim_count_)];
  claim.hyp = i;
  const auto first = static_cast<std::size_t>(claim_count_ * camera_count());
  std::fill_n(claim_margin_mm_.begin() + static_cast<std::ptrdiff_t>(first), camera_count(),
              -1.0);  // computed when first needed (take_claimed)
  std::fill_n(claim_unfit_.begin() + static_cast<std::ptrdiff_t>(first), camera_count(),
              std::uint8_t{0});
  const std::size_t per_cam = static_cast<std::size_t>(config_.max_points_per_camera);
  for (int c = 0; c < camera_count(); ++c) {
    const int j = set[c];
    if (j < 0 || j >= config_.max_points_per_camera) continue;
    int& slot = claim_of_[static_cast<std::size_t>(c) * per_cam + static_cast<std::size_t>(j)];
    if (slot < 0) slot = claim_count_;  // the first claim keeps a blob
  }
  ++claim_count_;
}

int MultiViewMerger::take_claimed(int i) noexcept {
  Point3& h = hyp_[static_cast<std::size_t>(i)];
  int cam[2] = {-1, -1};
  int k = 0;
  for (int c = 0; c < camera_count(); ++c) {
    const int j = h.blob_index[c];
    if (j < 0) continue;
    if (k == 2 || j >= config_.max_points_per_camera) return -1;
    cam[k++] = c;
  }
  if (k != 2) return -1;
  const std::size_t per_cam = static_cast<std::size_t>(config_.max_points_per_camera);
  const int a = claim_of_[static_cast<std::size_t>(cam[0]) * per_cam +
                          static_cast<std::size_t>(h.blob_index[cam[0]])];
  const int b = claim_of_[static_cast<std::size_t>(cam[1]) * per_cam +
                          static_cast<std::size_t>(h.blob_index[cam[1]])];
  if (a < 0 || a != b) return -1;
  Claim& claim = claims_[static_cast<std::size_t>(a)];
  const auto j = static_cast<std::size_t>(claim.hyp);
  const double moved_mm = (h.X_world - hyp_[j].X_world).norm();
  int unfit = 0;
  double* const margin_mm = claim_margin_mm_.data() + a * camera_count();
  std::uint8_t* const unfit_view = claim_unfit_.data() + a * camera_count();
  for (int c = 0; c < camera_count(); ++c) {
    if (c == cam[0] || c == cam[1]) continue;  // the pair's own views: not extended
    if (margin_mm[c] < 0.0) {                  // first need: the margin at the claim's point
      int u = 0;
      margin_mm[c] = claim_margin_mm(c, extended_[j][c], hyp_[j].X_world, u);
      unfit_view[c] = static_cast<std::uint8_t>(u);
    }
    if (!(moved_mm <= margin_mm[c])) return -1;
    unfit += unfit_view[c];  // cam[0], cam[1] are views of the claim: never unfit
  }
  // What extension and the duplicate lookup give: the claim's blobs, its hypothesis.
  const BlobRefs& set = extended_[j];
  counters_.views_added += static_cast<std::uint64_t>(set.count() - 2);
  counters_.unfit_views += static_cast<std::uint64_t>(unfit);
  ++counters_.claimed;
  extended_[static_cast<std::size_t>(i)] = set;
  h = hyp_[j];
  partial_views_[static_cast<std::size_t>(i)] = partial_views_[j];
  return claim.hyp;
}

bool MultiViewMerger::ties_a_claim(int keys) const noexcept {
  // Runs of exactly equal keys (but the index; NaN errors count as equal): the index
  // orders them, and a claim's copies (accepted right after it) could interleave with
  // the others. Harmless when every member has the same extended blob set: they are
  // copies of one hypothesis (the duplicate lookup), with the same outcome in any order.
  for (int r = 0; r < keys; ++r)  // NaN errors: the sort's order is not the reference's
    if (std::isnan(order_[static_cast<std::size_t>(r)].reproj_px)) return true;
  int start = 0;
  while (start < keys) {
    const AcceptKey& a = order_[static_cast<std::size_t>(start)];
    const BlobRefs& set = extended_[static_cast<std::size_t>(a.index)];
    bool copies = dup_head_[static_cast<std::size_t>(a.index)] >= 0, mixed = false;
    int end = start + 1;
    for (; end < keys; ++end) {
      const AcceptKey& b = order_[static_cast<std::size_t>(end)];
      if (b.views != a.views || b.partial != a.partial || a.reproj_px < b.reproj_px) break;
      copies = copies || dup_head_[static_cast<std::size_t>(b.index)] >= 0;
      mixed = mixed || !(extended_[static_cast<std::size_t>(b.index)] == set);
    }
    if (copies && mixed) return true;
    start = end;
  }
  return false;
}

bool MultiViewMerger::owns_a_blob(int o) const noexcept {
  const std::size_t per_cam = static_cast<std::size_t>(config_.max_points_per_camera);
  const BlobRefs& blobs =
      hyp_[static_cast<std::size_t>(out_hyp_[static_cast<std::size_t>(o)])].blob_index;
  for (int c = 0; c < camera_count(); ++c) {
    const int j = blobs[c];
    if (j >= 0 && j < config_.max_points_per_camera &&
        taken_by_[static_cast<std::size_t>(c) * per_cam + static_cast<std::size_t>(j)] == o)
      return true;
  }
  return false;
}

}  // namespace mocap
