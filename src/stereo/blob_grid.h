// Design: spatial index of one camera's blobs for the N-view merge's "nearest blob within
// r of a projection" lookups (multiview.h). A uniform grid of cell_px squares over the
// image; each cell holds a singly linked list of its blobs (head per cell, next per blob).
// Cells carry the frame's generation stamp, so a frame's build touches only its blobs'
// cells: O(n) per frame whatever the image size, nothing cleared, nothing allocated.
// Blobs outside the image fall into the border cells (the cell index is clamped, a
// monotone map, so a query rectangle clamped the same way still contains them).
// Non-finite blobs are left out: no finite radius contains them.
// Exactness: nearest() returns what the linear scan `for j: if (d2 <= best_d2) best = j`
// (best_d2 starting at r * r) returns: the largest index among the blobs of smallest d2
// with d2 <= r2, d2 computed by the same expression. The query rectangle is widened by a
// rounding margin, and a non-finite query (or one covering many cells) runs that scan.
// Empty lookups (most: a ghost's projections) stop at an occupancy bitmap of 8 px cells
// marking every cell within kOccupiedRadiusPx (8 px, plus a rounding margin) of a blob:
// a query of radius <= 8 px whose cell is unmarked has no blob within its radius (the
// answer the scan gives: -1, r^2). Clamped like the grid, so blobs and queries outside
// the image meet in the border cells.
// Capacity (max_blobs) is fixed at create(); build() ignores and counts further blobs.
#pragma once

#include <cstdint>
#include <vector>

#include "core/expected.h"
#include "core/types.h"

namespace mocap {

class BlobGrid {
 public:
  // Setup: the image size (px; 0 gives one cell), the cell size (px) and the capacity.
  static Expected<BlobGrid> create(int width_px, int height_px, double cell_px, int max_blobs);

  // One frame: indexes px[0..n). Blobs beyond the capacity are not indexed (the return
  // value is the number indexed, min(n, capacity)); px must outlive the queries.
  int build(const Vec2* px, int n) noexcept;

  // Among the indexed blobs j with d2 = |px[j] - q|^2 <= radius_px * radius_px: the one
  // of smallest d2, the largest j on ties; -1 when there is none. Writes its d2 (r^2
  // when there is none).
  int nearest(const Vec2& q, double radius_px, double& d2_out) const noexcept;

  // The same by the linear scan over every indexed blob (the reference).
  int nearest_scan(const Vec2& q, double radius_px, double& d2_out) const noexcept;

  // Radius (px) up to which an unmarked occupancy cell answers "none" (see above).
  static constexpr double kOccupiedRadiusPx = 8.0;

  int capacity() const noexcept { return static_cast<int>(next_.size()); }
  int size() const noexcept { return n_; }

 private:
  BlobGrid() = default;

  int gw_ = 1;
  int gh_ = 1;
  double inv_cell_ = 1.0;
  const Vec2* px_ = nullptr;
  int n_ = 0;
  std::uint32_t generation_ = 0;
  struct Cell {
    std::uint32_t stamp = 0;  // generation of `head`
    int head = -1;            // first blob, -1: none
  };
  std::vector<Cell> cells_;  // row-major, gw_ x gh_
  std::vector<int> next_;    // per blob: next blob of its cell, -1: last
  int fw_ = 1;               // occupancy cells (kOccupiedRadiusPx squares) per row
  int fh_ = 1;
  std::vector<std::uint64_t> occupied_;  // fw_ x fh_ bits, row-major
};

}  // namespace mocap
