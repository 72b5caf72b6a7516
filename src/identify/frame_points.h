// Design: the per-frame view of the measured points shared by every target's search:
// positions, the measured pair distances sorted ascending, ties by index (only pairs short enough
// to be any target's pair, and never two mutually exclusive points), each point's neighbours (the
// points it forms such a pair with, nearest first: a search for the points at a given distance from
// it bisects the list), a uniform grid of the points for radius queries (the temporal path's
// gates), and an occupancy state (points and per-camera blobs in use) that the depth-first search
// and the multi-body conflict resolution acquire and release. A point is available only when
// neither it nor any point sharing a blob with it is taken, which enforces "at most one of mutually
// exclusive candidates" and "a point belongs to at most one body" in one test. The
// points sharing a blob (each point's partners) are listed once per frame at load() (the
// frame's blobs numbered densely per camera, each view chained to the blob's previous
// one: linear in the views, no sort), so
// the test is one counter per point (blocked: acquisitions of the point and of its
// partners) and acquire/release touch the point and its few partners only.
// The grid's cell is the longest pair, so a pair's two points lie in neighbouring cells:
// building the pairs costs O(n * local density), not O(n^2), and a gate query visits at
// most 8 cells. Cells are hashed into 2 * capacity buckets (a collision only adds
// candidates that the distance test removes). All storage is sized at construction;
// load() and the queries allocate nothing.
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
  // `cameras`: the rig's camera count (1..kMaxCameras); the blob occupancy is sized by it
  // and a point's views of cameras at or above it are ignored.
  explicit FramePoints(int max_points, int cameras = kMaxCameras);

  struct LoadStats {
    int dropped = 0;  // beyond capacity
    int invalid = 0;  // non-finite
  };
  // Copies up to capacity points and builds the grid. Releases any previous occupancy.
  // The sorted list of the pairs no longer than max_pair_mm and the neighbour lists are
  // built by the first prepare_pairs() of the frame (a frame that the temporal path
  // settles entirely never needs them).
  LoadStats load(const MeasuredPoint* pts, int n, double max_pair_mm) noexcept;
  void prepare_pairs() noexcept;

  int size() const noexcept { return n_; }
  const Vec3& X(int i) const noexcept { return X_[static_cast<std::size_t>(i)]; }
  bool partial(int i) const noexcept { return partial_[static_cast<std::size_t>(i)] != 0; }
  const BlobRefs& blobs(int i) const noexcept { return blob_[static_cast<std::size_t>(i)]; }
  // After prepare_pairs():
  const PointPair* pairs() const noexcept { return pairs_.data(); }
  int pair_count() const noexcept { return pair_count_; }
  // The points forming a pair with i (within max_pair_mm, not exclusive), in ascending
  // (X(j) - X(i)).squaredNorm().
  const std::int16_t* neighbours(int i) const noexcept {
    return adj_.data() + adj_start_[static_cast<std::size_t>(i)];
  }
  int neighbour_count(int i) const noexcept {
    return adj_start_[static_cast<std::size_t>(i) + 1] - adj_start_[static_cast<std::size_t>(i)];
  }
  // Writes the available points strictly within radius_mm of c (at most cap of them,
  // ascending index) to out; returns how many there are in all (may exceed cap).
  int available_within(const Vec3& c, double radius_mm, std::int16_t* out, int cap) const noexcept;

  bool exclusive(int i, int j) const noexcept;
  bool available(int i) const noexcept {
    const auto s = static_cast<std::size_t>(i);
    return valid_[s] != 0 && blocked_[s] == 0;
  }
  // Acquisitions of point i and of the points sharing a blob with it (0: available if
  // valid; above 1 for a point one holds: someone else holds it or a blob of it).
  int uses(int i) const noexcept { return blocked_[static_cast<std::size_t>(i)]; }
  // The points sharing a blob with i (each once).
  int partner_count(int i) const noexcept {
    return part_start_[static_cast<std::size_t>(i) + 1] - part_start_[static_cast<std::size_t>(i)];
  }
  void acquire(int i) noexcept;
  void release(int i) noexcept;
  void release_all() noexcept;

 private:
  // One view of a point (load()'s partner lists): the point, its camera, and the
  // previous view of the same blob + 1 (0: the blob's first).
  struct View {
    std::int32_t prev_plus_one;
    std::int16_t point;
    std::int16_t camera;
  };
  static constexpr int kBlobSlots = 32768;  // every non-negative int16 blob index
  std::array<std::int64_t, 3> cell_of(const Vec3& x) const noexcept;
  std::uint32_t bucket_of(const std::array<std::int64_t, 3>& cell) const noexcept;
  void build_grid() noexcept;
  void build_pairs(double max2) noexcept;
  void build_partners() noexcept;
  // Calls f(i, j) once for every two points sharing a blob (listed at the lowest camera
  // whose blob they share).
  template <class F>
  void for_each_sharing(int views, F&& f) const noexcept;

  int capacity_;
  int n_ = 0;
  int pair_count_ = 0;
  double cell_mm_ = 1.0;
  double max_pair_mm_ = 0.0;
  bool pairs_ready_ = false;
  std::uint32_t bucket_mask_ = 0;
  std::vector<Vec3> X_;
  std::vector<BlobRefs> blob_;
  std::vector<std::uint8_t> valid_;
  std::vector<std::uint8_t> partial_;
  std::vector<std::uint16_t> point_uses_;
  std::vector<PointPair> pairs_;
  std::vector<std::int32_t> bucket_start_;  // counting sort of the points by bucket
  std::vector<std::int16_t> bucket_points_;
  std::vector<std::uint32_t> bucket_of_point_;
  std::vector<std::array<std::int64_t, 3>> cell_of_point_;
  std::vector<std::int32_t> adj_start_;  // CSR neighbour lists
  std::vector<std::int16_t> adj_;
  int cameras_;
  CameraMask camera_mask_;              // the cameras 0..cameras_-1
  std::vector<std::uint16_t> blocked_;  // acquisitions of the point and its partners
  std::vector<View> views_;             // every point's views, in point order
  // The last view + 1 of each blob of this frame: camera c's blob b at blob_start_[c] + b
  // (blob_start_: the frame's largest blob index + 1 per camera, summed; kept zeroed
  // between frames).
  std::vector<std::int32_t> last_view_;
  std::vector<std::int32_t> blob_start_;
  std::vector<std::int32_t> part_start_;  // CSR partner lists
  std::vector<std::int16_t> part_;
};

}  // namespace mocap
