// Design: see point_selection.h.
#include "track/point_selection.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <string>

namespace mocap {

Expected<PointSelector> PointSelector::create(int max_candidates, int max_blobs_per_camera,
                                              const PointSelectionConfig& c, int cameras) {
  if (max_candidates < 1) return make_error("stereo", "max_candidates", "must be >= 1");
  if (max_blobs_per_camera < 1)
    return make_error("stereo", "max_points_per_camera", "must be >= 1");
  if (cameras < 1 || cameras > kMaxCameras)
    return make_error("rig", "cameras", "must be 1.." + std::to_string(kMaxCameras));
  if (!(std::isfinite(c.max_speed_mm_per_s) && c.max_speed_mm_per_s >= 0.0))
    return make_error("selection", "max_speed_mm_per_s", "must be a non-negative number");
  if (!(std::isfinite(c.point_sigma_mm) && c.point_sigma_mm > 0.0))
    return make_error("selection", "point_sigma_mm", "must be a positive number");
  if (!(std::isfinite(c.max_gap_s) && c.max_gap_s > 0.0))
    return make_error("selection", "max_gap_s", "must be a positive number");
  PointSelector s;
  s.config_ = c;
  s.max_blobs_ = max_blobs_per_camera;
  s.cameras_ = cameras;
  s.taken_.assign(
      static_cast<std::size_t>(cameras) * static_cast<std::size_t>(max_blobs_per_camera), 0);
  s.keys_.resize(static_cast<std::size_t>(max_candidates));
  s.prev_.resize(static_cast<std::size_t>(max_candidates));
  return s;
}

bool PointSelector::free_blobs(const Point3& p) const noexcept {
  for (CameraMask m = p.blob_index.mask(); m != 0; m &= m - 1) {
    const int c = std::countr_zero(m);
    const int b = p.blob_index[c];
    if (c >= cameras_ || b >= max_blobs_ ||
        taken_[static_cast<std::size_t>(c * max_blobs_ + b)] != 0)
      return false;
  }
  return true;
}

void PointSelector::take(Point3& p) noexcept {
  p.reported = true;
  p.blob_index.for_each([&](int c, int b) {
    if (c < cameras_ && b < max_blobs_) taken_[static_cast<std::size_t>(c * max_blobs_ + b)] = 1;
  });
}

PointSelectionStats PointSelector::select(const BodyPoses& poses, std::int64_t timestamp_ns,
                                          PointList& points) noexcept {
  PointSelectionStats st;
  std::fill(taken_.begin(), taken_.end(), std::uint8_t{0});
  const int n = std::min(points.size(), static_cast<int>(keys_.size()));
  for (int i = 0; i < points.size(); ++i) points[i].reported = false;

  // Tier 0: the points of found bodies (mutually exclusive by identification).
  for (int b = 0; b < poses.count; ++b) {
    const BodyPose& body = poses.bodies[static_cast<std::size_t>(b)];
    if (!body.found) continue;
    for (std::int16_t idx : body.point_index_of_marker) {
      if (idx < 0 || idx >= n) continue;
      Point3& p = points[idx];
      if (p.reported || !free_blobs(p)) continue;
      take(p);
      ++st.by_body;
    }
  }
  // Tier 1: unambiguous candidates (their blobs are nobody else's).
  for (int i = 0; i < n; ++i) {
    Point3& p = points[i];
    if (p.reported || p.ambiguous || !free_blobs(p)) continue;
    take(p);
    ++st.unambiguous;
  }
  // Tier 2: temporal continuity, nearest to a previous reported point first.
  const double dt_s = static_cast<double>(timestamp_ns - prev_t_ns_) * 1e-9;
  int k = 0;
  if (config_.temporal && prev_count_ > 0 && dt_s > 0.0 && dt_s <= config_.max_gap_s) {
    const double gate = config_.max_speed_mm_per_s * dt_s + 4.0 * config_.point_sigma_mm;
    const double gate2 = gate * gate;
    for (int i = 0; i < n; ++i) {
      const Point3& p = points[i];
      if (p.reported || !free_blobs(p)) continue;
      double best2 = gate2;
      for (int j = 0; j < prev_count_; ++j)
        best2 = std::min(best2, (prev_[static_cast<std::size_t>(j)] - p.X_world).squaredNorm());
      if (best2 < gate2) keys_[static_cast<std::size_t>(k++)] = Key{best2, i};
    }
    std::sort(keys_.begin(), keys_.begin() + k,
              [](const Key& a, const Key& b) { return a.value < b.value; });
    for (int q = 0; q < k; ++q) {
      Point3& p = points[keys_[static_cast<std::size_t>(q)].index];
      if (!free_blobs(p)) continue;
      take(p);
      ++st.by_continuity;
    }
  }
  // Tier 3: mutual best epipolar fit among the candidates left.
  k = 0;
  for (int i = 0; i < n; ++i) {
    const Point3& p = points[i];
    if (!p.reported && free_blobs(p)) keys_[static_cast<std::size_t>(k++)] = Key{p.epipolar_px, i};
  }
  std::sort(keys_.begin(), keys_.begin() + k,
            [](const Key& a, const Key& b) { return a.value < b.value; });
  for (int q = 0; q < k; ++q) {
    Point3& p = points[keys_[static_cast<std::size_t>(q)].index];
    if (!free_blobs(p)) continue;
    take(p);
    ++st.by_epipolar;
  }
  // Remember what was reported for the next frame's continuity.
  prev_count_ = 0;
  for (int i = 0; i < n; ++i) {
    if (points[i].reported)
      prev_[static_cast<std::size_t>(prev_count_++)] = points[i].X_world;
    else
      ++st.rejected;
  }
  prev_t_ns_ = timestamp_ns;
  return st;
}

}  // namespace mocap
