// Design: see frame_points.h. The pair list is built in O(n^2) and sorted in place
// (std::sort allocates nothing); blob occupancy uses a counter per possible int16 blob
// index so that acquire/release are O(1) and exactly undo each other.
#include "identify/frame_points.h"

#include <algorithm>
#include <cmath>

namespace mocap {

FramePoints::FramePoints(int max_points)
    : capacity_(max_points),
      X_(static_cast<std::size_t>(max_points)),
      blob_(static_cast<std::size_t>(max_points)),
      valid_(static_cast<std::size_t>(max_points), 0),
      partial_(static_cast<std::size_t>(max_points), 0),
      point_uses_(static_cast<std::size_t>(max_points), 0),
      pairs_(static_cast<std::size_t>(max_points) * static_cast<std::size_t>(max_points - 1) / 2) {
  for (auto& uses : blob_uses_) uses.assign(kBlobSlots, 0);
}

FramePoints::LoadStats FramePoints::load(const MeasuredPoint* pts, int n,
                                         double max_pair_mm) noexcept {
  release_all();
  LoadStats stats;
  if (pts == nullptr || n < 0) n = 0;
  if (n > capacity_) {
    stats.dropped = n - capacity_;
    n = capacity_;
  }
  n_ = n;
  for (int i = 0; i < n; ++i) {
    const auto s = static_cast<std::size_t>(i);
    X_[s] = pts[i].X_world;
    blob_[s] = pts[i].blob_index;
    partial_[s] = pts[i].partial ? 1 : 0;
    valid_[s] = X_[s].allFinite() ? 1 : 0;
    if (!valid_[s]) ++stats.invalid;
    point_uses_[s] = 0;
  }
  const double max2 = max_pair_mm * max_pair_mm;
  int c = 0;
  for (int i = 0; i < n; ++i) {
    if (!valid_[static_cast<std::size_t>(i)]) continue;
    for (int j = i + 1; j < n; ++j) {
      if (!valid_[static_cast<std::size_t>(j)] || exclusive(i, j)) continue;
      const double d2 = (X(i) - X(j)).squaredNorm();
      if (d2 > max2) continue;
      pairs_[static_cast<std::size_t>(c++)] =
          PointPair{std::sqrt(d2), static_cast<std::int16_t>(i), static_cast<std::int16_t>(j)};
    }
  }
  pair_count_ = c;
  std::sort(pairs_.begin(), pairs_.begin() + c,
            [](const PointPair& a, const PointPair& b) { return a.d_mm < b.d_mm; });
  return stats;
}

bool FramePoints::exclusive(int i, int j) const noexcept {
  return blob_[static_cast<std::size_t>(i)].shares_blob(blob_[static_cast<std::size_t>(j)]);
}

bool FramePoints::available(int i) const noexcept {
  const auto s = static_cast<std::size_t>(i);
  if (!valid_[s] || point_uses_[s] != 0) return false;
  for (int c = 0; c < kMaxCameras; ++c) {
    const std::int16_t b = blob_[s][c];
    if (b >= 0 && blob_uses_[static_cast<std::size_t>(c)][static_cast<std::size_t>(b)] != 0)
      return false;
  }
  return true;
}

void FramePoints::acquire(int i) noexcept {
  const auto s = static_cast<std::size_t>(i);
  ++point_uses_[s];
  for (int c = 0; c < kMaxCameras; ++c) {
    const std::int16_t b = blob_[s][c];
    if (b >= 0) ++blob_uses_[static_cast<std::size_t>(c)][static_cast<std::size_t>(b)];
  }
}

void FramePoints::release(int i) noexcept {
  const auto s = static_cast<std::size_t>(i);
  if (point_uses_[s] == 0) return;
  --point_uses_[s];
  for (int c = 0; c < kMaxCameras; ++c) {
    const std::int16_t b = blob_[s][c];
    if (b >= 0 && blob_uses_[static_cast<std::size_t>(c)][static_cast<std::size_t>(b)] > 0)
      --blob_uses_[static_cast<std::size_t>(c)][static_cast<std::size_t>(b)];
  }
}

void FramePoints::release_all() noexcept {
  for (int i = 0; i < n_; ++i) {
    while (point_uses_[static_cast<std::size_t>(i)] != 0) release(i);
  }
}

}  // namespace mocap
