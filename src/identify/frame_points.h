// Design: the per-frame view of the measured points shared by every target's search:
// positions, the measured pair distances sorted ascending (only pairs short enough to
// be any target's pair, and never two mutually exclusive points), and an occupancy
// state (points and per-camera blobs in use) that the depth-first search and the
// multi-body conflict resolution acquire and release. A point is available only when
// neither it nor any blob it uses is taken, which enforces "at most one of mutually
// exclusive candidates" and "a point belongs to at most one body" in one test.
// All storage is sized at construction; load() and the queries allocate nothing.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "identify/identify_types.h"

namespace mocap {

struct PointPair {
  double d_mm;
  std::int16_t i;
  std::int16_t j;
};

class FramePoints {
 public:
  explicit FramePoints(int max_points);

  struct LoadStats {
    int dropped = 0;  // beyond capacity
    int invalid = 0;  // non-finite
  };
  // Copies up to capacity points and builds the sorted pair list of pairs no longer
  // than max_pair_mm. Releases any previous occupancy.
  LoadStats load(const MeasuredPoint* pts, int n, double max_pair_mm) noexcept;

  int size() const noexcept { return n_; }
  const Vec3& X(int i) const noexcept { return X_[static_cast<std::size_t>(i)]; }
  bool partial(int i) const noexcept { return partial_[static_cast<std::size_t>(i)] != 0; }
  const BlobRefs& blobs(int i) const noexcept { return blob_[static_cast<std::size_t>(i)]; }
  const PointPair* pairs() const noexcept { return pairs_.data(); }
  int pair_count() const noexcept { return pair_count_; }

  bool exclusive(int i, int j) const noexcept;
  bool available(int i) const noexcept;
  void acquire(int i) noexcept;
  void release(int i) noexcept;
  void release_all() noexcept;

 private:
  static constexpr int kBlobSlots = 32768;  // every non-negative int16 blob index
  int capacity_;
  int n_ = 0;
  int pair_count_ = 0;
  std::vector<Vec3> X_;
  std::vector<BlobRefs> blob_;
  std::vector<std::uint8_t> valid_;
  std::vector<std::uint8_t> partial_;
  std::vector<std::uint16_t> point_uses_;
  std::array<std::vector<std::uint16_t>, kMaxCameras> blob_uses_;  // per camera, per blob
  std::vector<PointPair> pairs_;
};

}  // namespace mocap
