// FramePoints' occupancy against its definition, on random frames where points share
// blobs often (few blobs per camera): after every acquire and release, a point is
// available exactly when it is valid and neither it nor any point sharing a blob with it
// is held, uses() is the acquisitions of the point and of the points sharing a blob with
// it, each sharing point is a partner once (however many blobs the two share), and
// release_all() and the next load() start from nothing. The pairs and each point's
// neighbours against their definition: every two valid points no farther apart than the
// bound and sharing no blob, the pairs by distance then index, each point's neighbours
// nearest first by the squared distance a search compares.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <tuple>
#include <vector>

#include "identify/frame_points.h"

namespace mocap {
namespace {

struct RandomFrame {
  std::vector<MeasuredPoint> pts;
};

RandomFrame random_frame(std::mt19937_64& rng, int n, int cameras, int blobs_per_camera) {
  RandomFrame f;
  std::uniform_real_distribution<double> x(-500.0, 500.0);
  std::uniform_int_distribution<int> blob(-1, blobs_per_camera - 1);  // -1: not seen
  std::uniform_int_distribution<int> percent(0, 99);
  for (int i = 0; i < n; ++i) {
    MeasuredPoint p;
    p.X_world = Vec3(x(rng), x(rng), x(rng));
    if (percent(rng) < 5) p.X_world.x() = std::numeric_limits<double>::quiet_NaN();
    for (int c = 0; c < cameras; ++c) p.blob_index.set(static_cast<std::size_t>(c), blob(rng));
    f.pts.push_back(p);
  }
  return f;
}

TEST(FramePoints, OccupancyFollowsItsDefinitionUnderRandomAcquireAndRelease) {
  std::mt19937_64 rng(11);
  constexpr int kCameras = 6;
  FramePoints frame(80, kCameras);
  int checks = 0, blocked_by_partner = 0;
  for (int trial = 0; trial < 60; ++trial) {
    const int n = 10 + trial % 50;
    const RandomFrame f = random_frame(rng, n, kCameras, 3 + trial % 12);
    frame.load(f.pts.data(), n, 300.0);
    std::vector<int> held(static_cast<std::size_t>(n), 0);
    std::vector<int> stack;
    const auto check = [&] {
      for (int i = 0; i < n; ++i) {
        const auto s = static_cast<std::size_t>(i);
        int ref = held[s], partners = 0;
        for (int j = 0; j < n; ++j) {
          if (j == i ||
              !f.pts[s].blob_index.shares_blob(f.pts[static_cast<std::size_t>(j)].blob_index))
            continue;
          ++partners;
          ref += held[static_cast<std::size_t>(j)];
        }
        const bool valid = f.pts[s].X_world.allFinite();
        ASSERT_EQ(frame.partner_count(i), partners) << "point " << i;
        ASSERT_EQ(frame.uses(i), ref) << "point " << i;
        ASSERT_EQ(frame.available(i), valid && ref == 0) << "point " << i;
        blocked_by_partner += held[s] == 0 && ref > 0;
        ++checks;
      }
    };
    std::uniform_int_distribution<int> point(0, n - 1);
    for (int op = 0; op < 40; ++op) {
      if (!stack.empty() && rng() % 3 == 0) {  // release the last one taken
        frame.release(stack.back());
        --held[static_cast<std::size_t>(stack.back())];
        stack.pop_back();
      } else {  // acquire any point, available or not (the conflict resolution does)
        const int p = point(rng);
        frame.acquire(p);
        ++held[static_cast<std::size_t>(p)];
        stack.push_back(p);
      }
      check();
    }
    frame.release(point(rng) == 0 ? 0 : n - 1);  // a release of a point not held: no-op
    if (held[0] == 0 && held[static_cast<std::size_t>(n - 1)] == 0) check();
    frame.release_all();
    std::fill(held.begin(), held.end(), 0);
    check();
  }
  EXPECT_GT(checks, 10000);
  EXPECT_GT(blocked_by_partner, 100) << "the frames share too few blobs to test anything";
}

TEST(FramePoints, ThePairsAndEachPointsNeighboursNearestFirstFollowTheirDefinition) {
  std::mt19937_64 rng(12);
  constexpr int kCameras = 4;
  constexpr double kMaxPairMm = 300.0;
  FramePoints frame(120, kCameras);
  int neighbours = 0, ties = 0, pair_ties = 0;
  for (int trial = 0; trial < 40; ++trial) {
    const int n = 20 + 2 * trial;
    RandomFrame f = random_frame(rng, n, kCameras, 20 + trial);
    // Some points on a lattice: many equal distances (and ties after the square root).
    for (int i = 0; i < n; i += 3)
      f.pts[static_cast<std::size_t>(i)].X_world =
          Vec3(25.0 * (i % 7), 25.0 * (i % 5), 12.5 * (i % 3)) - Vec3(0.1 * trial, 0.0, 0.0);
    frame.load(f.pts.data(), n, kMaxPairMm);
    frame.prepare_pairs();
    const auto X = [&](int i) -> const Vec3& { return f.pts[static_cast<std::size_t>(i)].X_world; };
    const auto pairs_with = [&](int i, int j) {
      return i != j && X(i).allFinite() && X(j).allFinite() &&
             !f.pts[static_cast<std::size_t>(i)].blob_index.shares_blob(
                 f.pts[static_cast<std::size_t>(j)].blob_index) &&
             (X(i) - X(j)).squaredNorm() <= kMaxPairMm * kMaxPairMm;
    };
    int pair_count = 0;
    for (int i = 0; i < n; ++i) {
      std::vector<int> ref;
      for (int j = 0; j < n; ++j)
        if (pairs_with(i, j)) ref.push_back(j);
      pair_count += static_cast<int>(ref.size());
      std::vector<int> got(frame.neighbours(i), frame.neighbours(i) + frame.neighbour_count(i));
      for (std::size_t e = 1; e < got.size(); ++e) {
        const double before = (X(got[e - 1]) - X(i)).squaredNorm();
        const double here = (X(got[e]) - X(i)).squaredNorm();
        ASSERT_LE(before, here) << "point " << i << ", neighbour " << e;
        ties += before == here;
      }
      std::sort(got.begin(), got.end());
      ASSERT_EQ(got, ref) << "point " << i;
      neighbours += static_cast<int>(got.size());
    }
    // The pairs: i < j, by distance, then by index (whatever the grid's order).
    std::vector<std::tuple<double, int, int>> ref_pairs;
    for (int i = 0; i < n; ++i)
      for (int j = i + 1; j < n; ++j)
        if (pairs_with(i, j)) ref_pairs.emplace_back(std::sqrt((X(i) - X(j)).squaredNorm()), i, j);
    std::sort(ref_pairs.begin(), ref_pairs.end());
    ASSERT_EQ(frame.pair_count() * 2, pair_count);
    ASSERT_EQ(static_cast<std::size_t>(frame.pair_count()), ref_pairs.size());
    for (int q = 0; q < frame.pair_count(); ++q) {
      const PointPair& pp = frame.pairs()[q];
      ASSERT_EQ(std::make_tuple(pp.d_mm, static_cast<int>(pp.i), static_cast<int>(pp.j)),
                ref_pairs[static_cast<std::size_t>(q)])
          << "pair " << q;
      pair_ties += q > 0 && frame.pairs()[q - 1].d_mm == pp.d_mm;
    }
  }
  EXPECT_GT(neighbours, 2000);
  EXPECT_GT(ties, 10) << "no equal distances: the order among them is not tested";
  EXPECT_GT(pair_ties, 10) << "no pairs of equal distance: their order is not tested";
}

}  // namespace
}  // namespace mocap
