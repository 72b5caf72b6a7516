// Design: see frame_points.h. The pairs come from the grid (each point against the
// points of its 27 neighbouring cells with a larger index, every bucket visited once; the
// points taken bucket by bucket, so the points of one cell share one collection of the
// neighbouring buckets) and are sorted in place by distance, then index (std::sort
// allocates nothing; the order does not depend on the grid's); the neighbour lists are a
// CSR array filled from the sorted pairs, nearest first.
// The partner lists come from the points' views chained per blob (last_view_ over the
// frame's dense blob numbering): a view whose blob has earlier views shares it with their
// points; a pair sharing blobs of several cameras is listed at its lowest shared camera
// only. acquire/release exactly undo each other.
#include "identify/frame_points.h"

#include <algorithm>
#include <bit>
#include <cmath>

namespace mocap {
namespace {
constexpr double kMaxCellIndex = 1e12;  // clamp of the cell coordinates (no overflow)

std::uint32_t bucket_count_for(int max_points) {
  std::uint32_t b = 16;
  while (b < 2u * static_cast<std::uint32_t>(max_points)) b *= 2;
  return b;
}

// Distinct buckets of the cells lo..hi (inclusive, per axis); false if more than 27 cells.
template <typename BucketOf>
int collect_buckets(const std::array<std::int64_t, 3>& lo, const std::array<std::int64_t, 3>& hi,
                    BucketOf bucket_of, std::array<std::uint32_t, 27>& out) {
  int n = 0;
  for (std::int64_t x = lo[0]; x <= hi[0]; ++x)
    for (std::int64_t y = lo[1]; y <= hi[1]; ++y)
      for (std::int64_t z = lo[2]; z <= hi[2]; ++z) {
        const std::uint32_t b = bucket_of(std::array<std::int64_t, 3>{x, y, z});
        bool seen = false;
        for (int s = 0; s < n && !seen; ++s) seen = out[static_cast<std::size_t>(s)] == b;
        if (!seen) out[static_cast<std::size_t>(n++)] = b;
      }
  return n;
}
}  // namespace

FramePoints::FramePoints(int max_points, int cameras)
    : capacity_(max_points),
      bucket_mask_(bucket_count_for(max_points) - 1),
      X_(static_cast<std::size_t>(max_points)),
      blob_(static_cast<std::size_t>(max_points)),
      valid_(static_cast<std::size_t>(max_points), 0),
      partial_(static_cast<std::size_t>(max_points), 0),
      point_uses_(static_cast<std::size_t>(max_points), 0),
      pairs_(static_cast<std::size_t>(max_points) * static_cast<std::size_t>(max_points - 1) / 2),
      bucket_start_(bucket_count_for(max_points) + 1, 0),
      bucket_points_(static_cast<std::size_t>(max_points), 0),
      bucket_of_point_(static_cast<std::size_t>(max_points), 0),
      cell_of_point_(static_cast<std::size_t>(max_points)),
      adj_start_(static_cast<std::size_t>(max_points) + 1, 0),
      adj_(pairs_.size() * 2, 0),
      cameras_(std::clamp(cameras, 1, kMaxCameras)),
      camera_mask_(cameras_ >= 32 ? ~CameraMask{0} : (CameraMask{1} << cameras_) - 1),
      blocked_(static_cast<std::size_t>(max_points), 0),
      views_(static_cast<std::size_t>(max_points) * static_cast<std::size_t>(cameras_)),
      last_view_(static_cast<std::size_t>(cameras_) * kBlobSlots, 0),
      blob_start_(static_cast<std::size_t>(cameras_) + 1, 0),
      part_start_(static_cast<std::size_t>(max_points) + 1, 0),
      part_(pairs_.size() * 2, 0) {}

std::array<std::int64_t, 3> FramePoints::cell_of(const Vec3& x) const noexcept {
  std::array<std::int64_t, 3> c{};
  for (int a = 0; a < 3; ++a)
    c[static_cast<std::size_t>(a)] = static_cast<std::int64_t>(
        std::floor(std::clamp(x[a] / cell_mm_, -kMaxCellIndex, kMaxCellIndex)));
  return c;
}

std::uint32_t FramePoints::bucket_of(const std::array<std::int64_t, 3>& c) const noexcept {
  const auto h = static_cast<std::uint64_t>(c[0]) * 73856093u ^
                 static_cast<std::uint64_t>(c[1]) * 19349663u ^
                 static_cast<std::uint64_t>(c[2]) * 83492791u;
  return static_cast<std::uint32_t>(h ^ (h >> 29)) & bucket_mask_;
}

void FramePoints::build_grid() noexcept {
  std::fill(bucket_start_.begin(), bucket_start_.end(), 0);
  for (int i = 0; i < n_; ++i) {
    const auto s = static_cast<std::size_t>(i);
    if (!valid_[s]) continue;
    cell_of_point_[s] = cell_of(X_[s]);
    bucket_of_point_[s] = bucket_of(cell_of_point_[s]);
    ++bucket_start_[bucket_of_point_[s] + 1];
  }
  for (std::size_t b = 1; b < bucket_start_.size(); ++b) bucket_start_[b] += bucket_start_[b - 1];
  // Fill (ascending point index within a bucket), then restore the starts.
  for (int i = 0; i < n_; ++i) {
    const auto s = static_cast<std::size_t>(i);
    if (valid_[s])
      bucket_points_[static_cast<std::size_t>(bucket_start_[bucket_of_point_[s]]++)] =
          static_cast<std::int16_t>(i);
  }
  for (std::size_t b = bucket_start_.size() - 1; b > 0; --b)
    bucket_start_[b] = bucket_start_[b - 1];
  bucket_start_[0] = 0;
}

void FramePoints::build_pairs(double max2) noexcept {
  int c = 0;
  std::fill(adj_start_.begin(), adj_start_.begin() + n_ + 1, 0);
  std::array<std::uint32_t, 27> buckets{};
  int nbk = 0;
  const std::array<std::int64_t, 3>* collected = nullptr;  // the cell `buckets` are around
  // The valid points bucket by bucket (the grid holds only those): a bucket's points are
  // usually one cell's, and share its neighbouring buckets.
  for (std::size_t pb = 0; pb + 1 < bucket_start_.size(); ++pb) {
    for (int pe = bucket_start_[pb]; pe < bucket_start_[pb + 1]; ++pe) {
      const int i = bucket_points_[static_cast<std::size_t>(pe)];
      const std::array<std::int64_t, 3>& cell = cell_of_point_[static_cast<std::size_t>(i)];
      if (collected == nullptr || *collected != cell) {
        auto lo = cell, hi = cell;
        for (std::size_t a = 0; a < 3; ++a) {
          --lo[a];
          ++hi[a];
        }
        nbk = collect_buckets(
            lo, hi, [this](const auto& x) { return bucket_of(x); }, buckets);
        collected = &cell;
      }
      for (int q = 0; q < nbk; ++q) {
        const std::uint32_t b = buckets[static_cast<std::size_t>(q)];
        for (int e = bucket_start_[b]; e < bucket_start_[b + 1]; ++e) {
          const int j = bucket_points_[static_cast<std::size_t>(e)];
          if (j <= i) continue;
          const double d2 = (X(i) - X(j)).squaredNorm();
          if (d2 > max2 || exclusive(i, j)) continue;
          pairs_[static_cast<std::size_t>(c++)] =
              PointPair{std::sqrt(d2), static_cast<std::int16_t>(i), static_cast<std::int16_t>(j)};
          ++adj_start_[static_cast<std::size_t>(i) + 1];
          ++adj_start_[static_cast<std::size_t>(j) + 1];
        }
      }
    }
  }
  pair_count_ = c;
  // By distance, then by index: an order of the pairs alone, whatever the grid's.
  std::sort(pairs_.begin(), pairs_.begin() + c, [](const PointPair& a, const PointPair& b) {
    return a.d_mm != b.d_mm ? a.d_mm < b.d_mm : a.i != b.i ? a.i < b.i : a.j < b.j;
  });
  for (int i = 0; i < n_; ++i)
    adj_start_[static_cast<std::size_t>(i) + 1] += adj_start_[static_cast<std::size_t>(i)];
  // Fill with a moving cursor per point (adj_start_[i + 1] temporarily) from the pairs in
  // ascending distance: each point's neighbours come nearest first.
  for (int p = 0; p < c; ++p) {
    const PointPair& pp = pairs_[static_cast<std::size_t>(p)];
    adj_[static_cast<std::size_t>(adj_start_[static_cast<std::size_t>(pp.i)]++)] = pp.j;
    adj_[static_cast<std::size_t>(adj_start_[static_cast<std::size_t>(pp.j)]++)] = pp.i;
  }
  for (int i = n_; i > 0; --i)
    adj_start_[static_cast<std::size_t>(i)] = adj_start_[static_cast<std::size_t>(i) - 1];
  adj_start_[0] = 0;
  // Sorted by the squared distance itself, (X(j) - X(i)).squaredNorm(), the value a
  // search compares (two squared distances may share a square root: the pairs' order
  // can then swap them). Nearly sorted already: an insertion sort is linear here.
  for (int i = 0; i < n_; ++i) {
    std::int16_t* a = adj_.data() + adj_start_[static_cast<std::size_t>(i)];
    const int na = neighbour_count(i);
    const auto d2 = [&](int j) noexcept { return (X(j) - X(i)).squaredNorm(); };
    for (int x = 1; x < na; ++x) {
      const std::int16_t v = a[x];
      const double key = d2(v);
      int y = x;
      for (; y > 0 && d2(a[y - 1]) > key; --y) a[y] = a[y - 1];
      a[y] = v;
    }
  }
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
    if ((blob_[s].mask() & ~camera_mask_) != 0) {  // a camera the rig does not have
      for (int c = cameras_; c < kMaxCameras; ++c) blob_[s].clear(static_cast<std::size_t>(c));
    }
    partial_[s] = pts[i].partial ? 1 : 0;
    valid_[s] = X_[s].allFinite() ? 1 : 0;
    if (!valid_[s]) ++stats.invalid;
    point_uses_[s] = 0;
    blocked_[s] = 0;
  }
  build_partners();
  // One cell for everything when the pair limit is unbounded (a plain O(n^2) build).
  cell_mm_ = !std::isfinite(max_pair_mm) ? 1e300 : std::max(max_pair_mm, 1e-3);
  build_grid();
  max_pair_mm_ = max_pair_mm;
  pairs_ready_ = false;
  pair_count_ = 0;
  return stats;
}

void FramePoints::prepare_pairs() noexcept {
  if (pairs_ready_) return;
  build_pairs(max_pair_mm_ * max_pair_mm_);
  pairs_ready_ = true;
}

int FramePoints::available_within(const Vec3& c, double radius_mm, std::int16_t* out,
                                  int cap) const noexcept {
  const double r2 = radius_mm * radius_mm;
  int found = 0;
  auto take = [&](int p) {
    if ((X(p) - c).squaredNorm() < r2 && available(p)) {
      if (found < cap) out[found] = static_cast<std::int16_t>(p);
      ++found;
    }
  };
  const auto lo = cell_of(c - Vec3::Constant(radius_mm));
  const auto hi = cell_of(c + Vec3::Constant(radius_mm));
  if (hi[0] - lo[0] > 2 || hi[1] - lo[1] > 2 || hi[2] - lo[2] > 2) {
    for (int p = 0; p < n_; ++p) take(p);  // a radius beyond a cell: plain scan
  } else {
    std::array<std::uint32_t, 27> buckets{};
    const int nbk = collect_buckets(
        lo, hi, [this](const auto& cell) { return bucket_of(cell); }, buckets);
    for (int q = 0; q < nbk; ++q) {
      const std::uint32_t b = buckets[static_cast<std::size_t>(q)];
      for (int e = bucket_start_[b]; e < bucket_start_[b + 1]; ++e)
        take(bucket_points_[static_cast<std::size_t>(e)]);
    }
  }
  const int kept = std::min(found, cap);
  for (int x = 1; x < kept; ++x)
    for (int y = x; y > 0 && out[y - 1] > out[y]; --y) std::swap(out[y - 1], out[y]);
  return found;
}

bool FramePoints::exclusive(int i, int j) const noexcept {
  return blob_[static_cast<std::size_t>(i)].shares_blob(blob_[static_cast<std::size_t>(j)]);
}

template <class F>
void FramePoints::for_each_sharing(int views, F&& f) const noexcept {
  for (int v = 0; v < views; ++v) {
    const View& view = views_[static_cast<std::size_t>(v)];
    const int i = view.point;
    const BlobRefs& a = blob_[static_cast<std::size_t>(i)];
    const CameraMask below = (CameraMask{1} << view.camera) - 1;
    for (int u = view.prev_plus_one - 1; u >= 0;
         u = views_[static_cast<std::size_t>(u)].prev_plus_one - 1) {
      const int j = views_[static_cast<std::size_t>(u)].point;
      const BlobRefs& b = blob_[static_cast<std::size_t>(j)];
      bool lower = false;  // they share a blob of a lower camera: listed there
      for (CameraMask m = a.mask() & b.mask() & below; m != 0 && !lower; m &= m - 1) {
        const int c = std::countr_zero(m);
        lower = a[c] == b[c];
      }
      if (!lower) f(i, j);
    }
  }
}

void FramePoints::build_partners() noexcept {
  // The frame's blobs, numbered densely per camera.
  std::fill(blob_start_.begin(), blob_start_.end(), 0);
  for (int i = 0; i < n_; ++i) {
    blob_[static_cast<std::size_t>(i)].for_each([&](int c, int b) {
      auto& top = blob_start_[static_cast<std::size_t>(c) + 1];
      top = std::max(top, b + 1);
    });
  }
  for (std::size_t c = 1; c < blob_start_.size(); ++c) blob_start_[c] += blob_start_[c - 1];
  // Each view chained to its blob's previous view (invalid points too: held, they block
  // their partners).
  int nv = 0;
  for (int i = 0; i < n_; ++i) {
    blob_[static_cast<std::size_t>(i)].for_each([&](int c, int b) {
      std::int32_t& last =
          last_view_[static_cast<std::size_t>(blob_start_[static_cast<std::size_t>(c)] + b)];
      views_[static_cast<std::size_t>(nv)] =
          View{last, static_cast<std::int16_t>(i), static_cast<std::int16_t>(c)};
      last = ++nv;
    });
  }
  std::fill(part_start_.begin(), part_start_.begin() + n_ + 1, 0);
  for_each_sharing(nv, [&](int i, int j) {
    ++part_start_[static_cast<std::size_t>(i) + 1];
    ++part_start_[static_cast<std::size_t>(j) + 1];
  });
  for (int i = 0; i < n_; ++i)
    part_start_[static_cast<std::size_t>(i) + 1] += part_start_[static_cast<std::size_t>(i)];
  // Fill with a moving cursor per point (part_start_[i] temporarily), then restore.
  for_each_sharing(nv, [&](int i, int j) {
    part_[static_cast<std::size_t>(part_start_[static_cast<std::size_t>(i)]++)] =
        static_cast<std::int16_t>(j);
    part_[static_cast<std::size_t>(part_start_[static_cast<std::size_t>(j)]++)] =
        static_cast<std::int16_t>(i);
  });
  for (int i = n_; i > 0; --i)
    part_start_[static_cast<std::size_t>(i)] = part_start_[static_cast<std::size_t>(i) - 1];
  part_start_[0] = 0;
  // Zeroed for the next frame: only the blobs this frame used.
  std::fill(last_view_.begin(), last_view_.begin() + blob_start_.back(), 0);
}

void FramePoints::acquire(int i) noexcept {
  const auto s = static_cast<std::size_t>(i);
  ++point_uses_[s];
  ++blocked_[s];
  for (int e = part_start_[s]; e < part_start_[s + 1]; ++e)
    ++blocked_[static_cast<std::size_t>(part_[static_cast<std::size_t>(e)])];
}

void FramePoints::release(int i) noexcept {
  const auto s = static_cast<std::size_t>(i);
  if (point_uses_[s] == 0) return;
  --point_uses_[s];
  --blocked_[s];
  for (int e = part_start_[s]; e < part_start_[s + 1]; ++e)
    --blocked_[static_cast<std::size_t>(part_[static_cast<std::size_t>(e)])];
}

void FramePoints::release_all() noexcept {
  std::fill(point_uses_.begin(), point_uses_.begin() + n_, 0);
  std::fill(blocked_.begin(), blocked_.begin() + n_, 0);
}

}  // namespace mocap
