// Design: see blob_grid.h.
#include "stereo/blob_grid.h"

#include <algorithm>
#include <cmath>
#include <string>

namespace mocap {
namespace {

// A query rectangle of more cells than this is answered by the linear scan.
constexpr int kGridMaxQueryCells = 64;

// floor(v * inv_cell) clamped to [0, cells): monotone in v (no floor() call: the
// truncation of a positive value is its floor).
int grid_cell(double v, double inv_cell, int cells) noexcept {
  const double t = v * inv_cell;
  if (!(t > 0.0)) return 0;
  if (t >= static_cast<double>(cells)) return cells - 1;
  return static_cast<int>(t);
}

}  // namespace

Expected<BlobGrid> BlobGrid::create(int width_px, int height_px, double cell_px, int max_blobs) {
  if (!(cell_px > 0.0) || !std::isfinite(cell_px))
    return Error{"blob grid: cell_px must be a positive number"};
  if (max_blobs < 1) return Error{"blob grid: max_blobs must be positive"};
  if (width_px < 0 || height_px < 0) return Error{"blob grid: negative image size"};
  BlobGrid g;
  g.gw_ = std::max(1, static_cast<int>(std::ceil(width_px / cell_px)));
  g.gh_ = std::max(1, static_cast<int>(std::ceil(height_px / cell_px)));
  g.inv_cell_ = 1.0 / cell_px;
  const auto cells = static_cast<std::size_t>(g.gw_) * static_cast<std::size_t>(g.gh_);
  g.cells_.assign(cells, Cell{});
  g.next_.assign(static_cast<std::size_t>(max_blobs), -1);
  g.fw_ = std::max(1, static_cast<int>(std::ceil(width_px / kOccupiedRadiusPx)));
  g.fh_ = std::max(1, static_cast<int>(std::ceil(height_px / kOccupiedRadiusPx)));
  const auto bits = static_cast<std::size_t>(g.fw_) * static_cast<std::size_t>(g.fh_);
  g.occupied_.assign((bits + 63) / 64, 0);
  return g;
}

int BlobGrid::build(const Vec2* px, int n) noexcept {
  px_ = px;
  n_ = std::clamp(n, 0, capacity());
  if (px == nullptr) n_ = 0;
  if (++generation_ == 0) {  // wrapped: forget every stamp once
    for (Cell& cell : cells_) cell.stamp = 0;
    generation_ = 1;
  }
  // Inserted in descending index order, so each cell lists its blobs in ascending order.
  for (int j = n_ - 1; j >= 0; --j) {
    const Vec2& p = px[j];
    if (!std::isfinite(p.x()) || !std::isfinite(p.y())) continue;
    const auto cell =
        static_cast<std::size_t>(grid_cell(p.y(), inv_cell_, gh_)) * static_cast<std::size_t>(gw_) +
        static_cast<std::size_t>(grid_cell(p.x(), inv_cell_, gw_));
    Cell& c = cells_[cell];
    if (c.stamp != generation_) {
      c.stamp = generation_;
      c.head = -1;
    }
    next_[static_cast<std::size_t>(j)] = c.head;
    c.head = j;
  }
  // Occupancy: every cell the square of kOccupiedRadiusPx (+ rounding) around a blob meets.
  std::fill(occupied_.begin(), occupied_.end(), 0);
  constexpr double inv = 1.0 / kOccupiedRadiusPx;
  for (int j = 0; j < n_; ++j) {
    const Vec2& p = px[j];
    if (!std::isfinite(p.x()) || !std::isfinite(p.y())) continue;
    const double w =
        kOccupiedRadiusPx * (1.0 + 1e-9) + 1e-6 + 1e-9 * (std::abs(p.x()) + std::abs(p.y()));
    const int x0 = grid_cell(p.x() - w, inv, fw_), x1 = grid_cell(p.x() + w, inv, fw_);
    const int y0 = grid_cell(p.y() - w, inv, fh_), y1 = grid_cell(p.y() + w, inv, fh_);
    for (int y = y0; y <= y1; ++y)
      for (int x = x0; x <= x1; ++x) {
        const std::size_t bit = static_cast<std::size_t>(y) * static_cast<std::size_t>(fw_) +
                                static_cast<std::size_t>(x);
        occupied_[bit >> 6] |= std::uint64_t{1} << (bit & 63);
      }
  }
  return n_;
}

int BlobGrid::nearest_scan(const Vec2& q, double radius_px, double& d2_out) const noexcept {
  int best = -1;
  double best_d2 = radius_px * radius_px;
  for (int j = 0; j < n_; ++j) {
    const double d2 = (px_[j] - q).squaredNorm();
    if (d2 <= best_d2) {
      best_d2 = d2;
      best = j;
    }
  }
  d2_out = best_d2;
  return best;
}

int BlobGrid::nearest(const Vec2& q, double radius_px, double& d2_out) const noexcept {
  if (std::abs(radius_px) <= kOccupiedRadiusPx && std::isfinite(q.x()) && std::isfinite(q.y())) {
    constexpr double inv = 1.0 / kOccupiedRadiusPx;
    const std::size_t bit =
        static_cast<std::size_t>(grid_cell(q.y(), inv, fh_)) * static_cast<std::size_t>(fw_) +
        static_cast<std::size_t>(grid_cell(q.x(), inv, fw_));
    if ((occupied_[bit >> 6] >> (bit & 63) & 1u) == 0) {  // no blob within the radius
      d2_out = radius_px * radius_px;
      return -1;
    }
  }
  // A blob with d2 <= r^2 (rounded) lies within |r| of q up to rounding: widen by far more.
  const double w =
      std::abs(radius_px) * (1.0 + 1e-9) + 1e-9 + 1e-12 * (std::abs(q.x()) + std::abs(q.y()));
  if (!std::isfinite(w) || !std::isfinite(q.x()) || !std::isfinite(q.y()))
    return nearest_scan(q, radius_px, d2_out);
  const int x0 = grid_cell(q.x() - w, inv_cell_, gw_), x1 = grid_cell(q.x() + w, inv_cell_, gw_);
  const int y0 = grid_cell(q.y() - w, inv_cell_, gh_), y1 = grid_cell(q.y() + w, inv_cell_, gh_);
  if ((x1 - x0 + 1) * (y1 - y0 + 1) > kGridMaxQueryCells) return nearest_scan(q, radius_px, d2_out);
  int best = -1;
  double best_d2 = radius_px * radius_px;
  const Cell* cells = cells_.data();
  const int* next = next_.data();
  for (int y = y0; y <= y1; ++y) {
    const std::size_t row = static_cast<std::size_t>(y) * static_cast<std::size_t>(gw_);
    for (int x = x0; x <= x1; ++x) {
      const Cell& cell = cells[row + static_cast<std::size_t>(x)];
      if (cell.stamp != generation_) continue;
      for (int j = cell.head; j >= 0; j = next[static_cast<std::size_t>(j)]) {
        const double d2 = (px_[j] - q).squaredNorm();
        if (d2 < best_d2 || (d2 == best_d2 && j > best)) {  // the scan's `<=`: last j wins
          best_d2 = d2;
          best = j;
        }
      }
    }
  }
  d2_out = best_d2;
  return best;
}

}  // namespace mocap
