// Design: see undistorted_blobs.h.
#include "stereo/undistorted_blobs.h"

#include <algorithm>
#include <cmath>

namespace mocap {

Expected<BlobUndistorter> BlobUndistorter::create(const CameraModel& camera, int max_points) {
  if (max_points < 1 || max_points > 32767)
    return make_error("stereo", "max_points_per_camera", "must be in [1, 32767]");
  BlobUndistorter u;
  u.camera_ = camera;
  u.xn_.assign(static_cast<std::size_t>(max_points), Vec2::Zero());
  u.valid_.assign(static_cast<std::size_t>(max_points), 0);
  return u;
}

UndistortedBlobs BlobUndistorter::undistort(const Vec2* px, int n) noexcept {
  UndistortedBlobs v;
  v.px = px;
  v.received = n;
  v.xn = xn_.data();
  v.valid = valid_.data();
  if (px == nullptr || n <= 0) return v;
  v.count = std::min(n, capacity());
  for (int i = 0; i < v.count; ++i) {
    const auto k = static_cast<std::size_t>(i);
    valid_[k] = undistort_one(px[i], xn_[k]);
  }
  return v;
}

std::uint8_t BlobUndistorter::undistort_one(const Vec2& p, Vec2& xn) const noexcept {
  return std::isfinite(p.x()) && std::isfinite(p.y()) && undistort_pixel(camera_, p, xn) ? 1 : 0;
}

UndistortedStore BlobUndistorter::make_store() const {
  UndistortedStore s;
  s.xn.assign(xn_.size(), Vec2::Zero());
  s.valid.assign(valid_.size(), 0);
  return s;
}

}  // namespace mocap
