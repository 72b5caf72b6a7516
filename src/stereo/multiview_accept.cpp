// Design: the N-view merge's step 4, the acceptance (multiview.h): a hypothesis taken in
// acceptance order is emitted, or merged with a taken point (the same blobs), or known as
// the owner's marker paired through its unfit view, or rejected as a ghost of a point seen
// by more cameras; two balls whose images merged in some views are split first.
// noexcept, no allocation.
#include <algorithm>

#include "stereo/multiview.h"

namespace mocap {

// Step 4 for hypothesis i (see the design comment); true when it was taken (emitted).
bool MultiViewMerger::accept(int i, const Vec2* const* px, PointList& out,
                             bool& complete) noexcept {
  const std::size_t per_cam = static_cast<std::size_t>(config_.max_points_per_camera);
  {
    Point3 h = hyp_[static_cast<std::size_t>(i)];
    const int views = views_[static_cast<std::size_t>(i)];
    // The taken points using one of h's blobs (at most one per camera).
    int owners[kMaxCameras];
    int n_owners = 0;
    bool richer_owner = false;
    for (int c = 0; c < camera_count(); ++c) {
      const int j = h.blob_index[c];
      if (j < 0) continue;
      const int o =
          j < config_.max_points_per_camera
              ? taken_by_[static_cast<std::size_t>(c) * per_cam + static_cast<std::size_t>(j)]
              : -1;
      if (o < 0) continue;
      if (std::find(owners, owners + n_owners, o) == owners + n_owners) owners[n_owners++] = o;
      richer_owner = richer_owner || out[o].blob_index.count() > views;
    }
    // The same point: the blobs of a taken point's hypothesis, or, for a point that gave
    // views up (split_from_owners), exactly the views it kept.
    const bool same_as_taken = std::any_of(owners, owners + n_owners, [&](int o) {
      return hyp_[static_cast<std::size_t>(out_hyp_[static_cast<std::size_t>(o)])].blob_index ==
                 h.blob_index ||
             out[o].blob_index == h.blob_index;
    });
    if (same_as_taken) {
      ++counters_.merged;  // the same blobs: the same point from another pair
      return false;
    }
    if (n_owners == 1 && is_unfit_pairing(i, out[owners[0]], px)) {
      ++counters_.unfit_pairings;  // the owner's marker, paired through its unfit view
      return false;
    }
    if (n_owners > 0 && split_from_owners(h, owners, n_owners, out, px)) {
      ++counters_.shared_views_split;  // another marker's blob merged with this one's
      n_owners = 0;
      richer_owner = false;
    }
    if (richer_owner) {
      ++counters_.ghosts_rejected;  // a blob of a point that more cameras confirm
      return false;
    }
    h.ambiguous = n_owners > 0;
    h.reported = !h.ambiguous;
    if (out.size() >= out.capacity() || static_cast<std::size_t>(out.size()) >= out_hyp_.size()) {
      ++counters_.point_overflow;
      complete = false;
      return false;
    }
    const int index = out.size();
    for (int c = 0; c < camera_count(); ++c) {
      const int j = h.blob_index[c];
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
    out_hyp_[static_cast<std::size_t>(index)] = i;
    out.push_back(h);
    ++counters_.points;
    return true;
  }
}

bool MultiViewMerger::is_unfit_pairing(int i, const Point3& o,
                                       const Vec2* const* px) const noexcept {
  const BlobRefs& mine = hyp_[static_cast<std::size_t>(i)].blob_index;
  bool any_unfit = false;
  for (int c = 0; c < camera_count(); ++c) {
    const int j = mine[c];
    if (j < 0 || j == o.blob_index[c]) continue;
    if (o.blob_index[c] >= 0) return false;  // o sees another blob there: a rival view
    // Within the ball's image (+ the gate) around o's projection: part of o's image, a
    // partly hidden or split piece of it.
    Vec2 q;
    if (!project(cams_[static_cast<std::size_t>(c)], o.X_world, q)) return false;
    const double gate = unfit_gate_px(c, o.X_world);
    if ((px[c][j] - q).squaredNorm() > gate * gate) return false;
    any_unfit = true;
  }
  return any_unfit;
}

bool MultiViewMerger::split_from_owners(Point3& h, const int* owners, int n_owners,
                                        const PointList& out,
                                        const Vec2* const* px) const noexcept {
  const double diameter_mm = 2.0 * config_.marker_radius_mm;
  if (diameter_mm <= 0.0) return false;
  BlobRefs own = h.blob_index;  // h's views whose blob no taken point uses
  for (int k = 0; k < n_owners; ++k) {
    const Point3& o = out[owners[k]];
    int shared = 0;
    for (int c = 0; c < camera_count(); ++c) {
      if (h.blob_index[c] < 0 || h.blob_index[c] != o.blob_index[c]) continue;
      own[c] = -1;
      ++shared;
    }
    // The owner must stand on two views of its own, and be another ball: two balls are
    // at least a diameter apart.
    if (o.blob_index.count() - shared < 2) return false;
    if ((o.X_world - h.X_world).norm() < diameter_mm) return false;
  }
  if (own.count() < 2) return false;
  Point3 p = h;
  p.blob_index = own;
  if (!refit(p, px) || p.reproj_px > config_.gate_px) return false;
  for (int k = 0; k < n_owners; ++k)
    if ((out[owners[k]].X_world - p.X_world).norm() < diameter_mm) return false;
  h = p;
  return true;
}

}  // namespace mocap
