// Design: one camera's blobs undistorted once per frame, for every camera pair it is in.
// With N cameras each camera belongs to N - 1 pairs; undistorting its blobs in each pair
// (an iterative inversion of the lens model per blob) was most of the pairs' cost at 8
// cameras. A BlobUndistorter per camera fills preallocated arrays; the UndistortedBlobs
// view it returns is what StereoTriangulator::process takes, and the pair's result is
// bit for bit the one from distorted pixels (the same undistort_pixel() on the same
// input; the pair then derives everything else as before).
// Capacity is fixed at create(); undistort() is noexcept and allocation-free; blobs beyond
// the capacity are not undistorted (the view says how many were received).
#pragma once

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

class BlobUndistorter {
 public:
  static Expected<BlobUndistorter> create(const CameraModel& camera, int max_points);
  BlobUndistorter() = default;  // capacity 0: undistorts nothing

  // Undistorts px[0..min(n, capacity)); px must outlive the returned view.
  UndistortedBlobs undistort(const Vec2* px, int n) noexcept;

  int capacity() const noexcept { return static_cast<int>(xn_.size()); }
  const CameraModel& camera() const noexcept { return camera_; }

 private:
  CameraModel camera_;
  std::vector<Vec2> xn_;
  std::vector<std::uint8_t> valid_;
};

}  // namespace mocap
