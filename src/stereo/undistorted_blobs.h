// Design: one camera's blobs undistorted once per frame, for every camera pair it is in.
// With N cameras each camera belongs to N - 1 pairs; undistorting its blobs in each pair
// (an iterative inversion of the lens model per blob) was most of the pairs' cost at 8
// cameras. A BlobUndistorter per camera fills preallocated arrays; the UndistortedBlobs
// view it returns is what StereoTriangulator::process takes, and the pair's result is
// bit for bit the one from distorted pixels (the same undistort_pixel() on the same
// input; the pair then derives everything else as before).
// Capacity is fixed at create(); undistort() is noexcept and allocation-free; blobs beyond
// the capacity are not undistorted (the view says how many were received).
// UndistortedStore: the same arrays owned by the caller, for undistortion where the blobs
// are made (a detection thread) and handed on with them (undistort_into(), const: any
// thread); its view() is the view undistort() of the same blobs returns, bit for bit.
#pragma once

#include <algorithm>
#include <cstdint>
#include <vector>

#include "camera/camera_model.h"
#include "core/expected.h"
#include "core/types.h"

namespace mocap {

// A view of one camera's undistorted blobs (valid until the next undistort()).
struct UndistortedBlobs {
  const Vec2* px = nullptr;             // the blobs as received (distorted pixels)
  int received = 0;                     // blobs received (may exceed `count`; < 0: bad input)
  int count = 0;                        // blobs undistorted: [0, count)
  const Vec2* xn = nullptr;             // normalised undistorted (x', y'), valid ones only
  const std::uint8_t* valid = nullptr;  // 1: finite and undistorted, 0: undistortion failed
};

// One camera's undistorted blobs in buffers of their own (see the top). received < 0:
// none made (the consumer undistorts itself).
struct UndistortedStore {
  std::vector<Vec2> xn;
  std::vector<std::uint8_t> valid;
  int received = -1;
  int count = 0;
  // The view of px[0..received) (px: the same blobs as given to undistort_into()).
  UndistortedBlobs view(const Vec2* px) const noexcept {
    return UndistortedBlobs{px, received, count, xn.data(), valid.data()};
  }
};

class BlobUndistorter {
 public:
  static Expected<BlobUndistorter> create(const CameraModel& camera, int max_points);
  BlobUndistorter() = default;  // capacity 0: undistorts nothing

  // Undistorts px[0..min(n, capacity)); px must outlive the returned view.
  UndistortedBlobs undistort(const Vec2* px, int n) noexcept;

  // The same into `out` (its arrays sized to capacity() by make_store()): blob i at
  // (blobs[i].x, blobs[i].y) via px_of(i) for i < min(n, capacity()). Thread-safe.
  template <class PxOf>
  void undistort_into(PxOf&& px_of, int n, UndistortedStore& out) const noexcept {
    out.received = n;
    out.count = n > 0 ? std::min(n, capacity()) : 0;
    if (out.xn.size() < static_cast<std::size_t>(out.count) ||
        out.valid.size() < static_cast<std::size_t>(out.count)) {
      out.received = -1;  // a store not made for this camera: none
      return;
    }
    for (int i = 0; i < out.count; ++i) {
      const auto k = static_cast<std::size_t>(i);
      const Vec2 p = px_of(i);
      out.valid[k] = undistort_one(p, out.xn[k]);
    }
  }
  UndistortedStore make_store() const;

  int capacity() const noexcept { return static_cast<int>(xn_.size()); }
  const CameraModel& camera() const noexcept { return camera_; }

 private:
  // 1: p finite and undistorted into xn; 0: not.
  std::uint8_t undistort_one(const Vec2& p, Vec2& xn) const noexcept;

  CameraModel camera_;
  std::vector<Vec2> xn_;
  std::vector<std::uint8_t> valid_;
};

}  // namespace mocap
