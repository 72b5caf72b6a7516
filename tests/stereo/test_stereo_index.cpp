// Design: the indexed correspondence and merge (blob_grid.h, blob_set_index.h, the
// shared per-camera undistortion of undistorted_blobs.h) give exactly the result of the
// linear scans they replace. Property tests over many random scenes of "the whole robot"
// (2..8 cameras on a ring 2.5-3.5 m around a humanoid volume, 5..130 markers, views
// missing, stray, split and duplicate blobs):
//  - the new path (undistorted once per camera, sorted sweep, indexed merge, pair by
//    pair: the pairs skip settled candidates) and the previous one (each pair undistorts,
//    linear-scan merge, the pairs' lists at once: the merge skips them) agree bit for bit:
//    every point, in order (X_world, errors, blob per camera, flags), and every counter
//    but `settled`; the pairs skipped every candidate the merge found settled;
//  - both agree with the brute force of everything (all n*m pairs, linear scans) on the
//    set of points, in scenes without exact duplicate blobs (with them, hypotheses tie
//    exactly and the merge breaks the tie by the pairs' candidate order, which differs
//    between the sorted sweep and the n*m loop, before and after the index alike);
//  - the grid's nearest-blob query equals the linear scan on random queries, including
//    blobs outside the image, non-finite blobs, exact ties and huge radii; the hash
//    lookup equals the linear search for the first equal blob set.
// Steady-state processing allocates nothing.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <random>
#include <vector>

#include "stereo/blob_grid.h"
#include "stereo/blob_set_index.h"
#include "stereo/undistorted_blobs.h"
#include "tests/stereo/humanoid_scene.h"
#include "tests/stereo/rig_stereo_stage.h"
#include "tests/support/alloc_counter.h"

namespace mocap {
namespace {

bool same_bits(double a, double b) { return std::memcmp(&a, &b, sizeof(a)) == 0; }

bool identical(const Point3& a, const Point3& b) {
  return same_bits(a.X_world.x(), b.X_world.x()) && same_bits(a.X_world.y(), b.X_world.y()) &&
         same_bits(a.X_world.z(), b.X_world.z()) && same_bits(a.reproj_px, b.reproj_px) &&
         same_bits(a.epipolar_px, b.epipolar_px) && a.blob_index == b.blob_index &&
         a.ambiguous == b.ambiguous && a.reported == b.reported;
}

bool by_blobs(const Point3& a, const Point3& b) {
  return std::lexicographical_compare(a.blob_index.indices().begin(), a.blob_index.indices().end(),
                                      b.blob_index.indices().begin(), b.blob_index.indices().end());
}

std::vector<Point3> sorted(const PointList& l) {
  std::vector<Point3> v(l.begin(), l.end());
  std::stable_sort(v.begin(), v.end(), by_blobs);
  return v;
}

// Every counter but `settled` (pair by pair, the pairs skip those candidates: the merge
// never sees them).
bool same_counters(MultiViewCounters a, MultiViewCounters b) {
  a.settled = b.settled = 0;
  return std::memcmp(&a, &b, sizeof(a)) == 0;
}

bool same_counters(const StereoCounters& a, const StereoCounters& b) {
  return std::memcmp(&a, &b, sizeof(a)) == 0;
}

TEST(StereoIndex, IndexedPathEqualsThePreviousAndTheBruteForceOnRandomScenes) {
  std::mt19937 rng(20261204);
  int scenes = 0, points = 0, multi = 0, brute_compared = 0;
  for (int s = 0; s < 120; ++s) {
    const int cameras = 2 + s % 7;
    const Rig rig = test::random_ring_rig(cameras, rng);
    test::SceneOptions so = test::random_scene(130, 6, 0.25, rng);
    so.split = 0.05;
    // Exact duplicate blobs (every third scene) tie hypotheses exactly; the merge breaks
    // such ties by hypothesis order, which follows the pairs' candidate order (the sorted
    // sweep's differs from the n*m loop's): compared with the previous path only.
    so.duplicate = s % 3 == 2 ? 0.02 : 0.0;
    test::RigStereoStage fresh(rig, test::kIndexedPath), previous(rig, test::kLinearMergePath),
        brute(rig, test::kBruteForcePath), pair_undistort(rig, test::kPairUndistortPath);
    std::uint64_t settled_before = 0;
    for (int f = 0; f < 2; ++f) {
      const auto px = test::humanoid_frame(rig, so, rng);
      fresh.run(px);
      previous.run(px);
      brute.run(px);
      pair_undistort.run(px);
      SCOPED_TRACE(::testing::Message() << "scene " << s << " frame " << f << ", " << cameras
                                        << " cameras, " << so.markers << " markers");
      // Candidates the fresh path's pairs emitted, and the previous path's (every pair).
      std::uint64_t emitted = 0, emitted_all = 0;
      for (std::size_t k = 0; k < fresh.pairs.size(); ++k) {
        // The shared undistortion equals every pair's own (both pair by pair).
        const PointList& a = fresh.pair_out[k];
        const PointList& u = pair_undistort.pair_out[k];
        ASSERT_EQ(a.size(), u.size()) << "pair " << k;
        for (int i = 0; i < a.size(); ++i) ASSERT_TRUE(identical(a[i], u[i])) << "pair " << k;
        ASSERT_TRUE(same_counters(fresh.pairs[k].counters(), pair_undistort.pairs[k].counters()));
        emitted += static_cast<std::uint64_t>(a.size());
        emitted_all += static_cast<std::uint64_t>(previous.pair_out[k].size());
        // The sweep finds the n*m loop's pairs (both given as lists: every pair tried).
        const auto sa = sorted(previous.pair_out[k]), sb = sorted(brute.pair_out[k]);
        ASSERT_EQ(sa.size(), sb.size()) << "pair " << k;
        for (std::size_t i = 0; i < sa.size(); ++i) ASSERT_TRUE(identical(sa[i], sb[i]));
      }
      // The candidates the merge of the lists found settled are exactly those the pairs
      // given SettledBlobs did not emit.
      ASSERT_EQ(emitted_all - emitted, previous.merger.counters().settled - settled_before);
      settled_before = previous.merger.counters().settled;
      ASSERT_EQ(fresh.out.size(), previous.out.size());
      for (int i = 0; i < fresh.out.size(); ++i)
        ASSERT_TRUE(identical(fresh.out[i], previous.out[i])) << "point " << i;
      ASSERT_TRUE(same_counters(fresh.merger.counters(), previous.merger.counters()));
      ASSERT_EQ(fresh.out.size(), pair_undistort.out.size());
      for (int i = 0; i < fresh.out.size(); ++i)
        ASSERT_TRUE(identical(fresh.out[i], pair_undistort.out[i])) << "point " << i;
      if (so.duplicate == 0.0) {
        const auto sf = sorted(fresh.out), sb = sorted(brute.out);
        ASSERT_EQ(sf.size(), sb.size());
        for (std::size_t i = 0; i < sf.size(); ++i) ASSERT_TRUE(identical(sf[i], sb[i]));
        ++brute_compared;
      }
      points += fresh.out.size();
      for (const Point3& p : fresh.out) multi += p.blob_index.count() >= 3;
    }
    ++scenes;
  }
  EXPECT_EQ(scenes, 120);
  EXPECT_EQ(brute_compared, 2 * 80);
  EXPECT_GT(multi, points / 2);  // the scenes exercise the N-view merge, not only pairs
}

TEST(StereoIndex, GridNearestEqualsTheLinearScan) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> ux(-40.0, 1320.0), uy(-40.0, 1064.0), u01(0.0, 1.0);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  auto grid = BlobGrid::create(1280, 1024, 32.0, 300).value();
  int found = 0;
  for (int frame = 0; frame < 200; ++frame) {
    std::vector<Vec2> px;
    const int n = static_cast<int>(rng() % 320);  // sometimes beyond the capacity
    for (int j = 0; j < n; ++j) {
      const double r = u01(rng);
      if (r < 0.02)
        px.push_back(Vec2(nan, uy(rng)));
      else if (r < 0.03)
        px.push_back(Vec2(inf, -inf));
      else if (r < 0.10 && !px.empty())
        px.push_back(px[rng() % px.size()]);  // an exact tie
      else if (r < 0.12)
        px.push_back(Vec2(1e12 * (u01(rng) - 0.5), uy(rng)));
      else if (r < 0.20)  // on a cell border
        px.push_back(Vec2(32.0 * static_cast<int>(ux(rng) / 32.0), uy(rng)));
      else
        px.push_back(Vec2(ux(rng), uy(rng)));
    }
    ASSERT_EQ(grid.build(px.data(), n), std::min(n, 300));
    for (int q = 0; q < 100; ++q) {
      Vec2 at(ux(rng), uy(rng));
      const double radii[] = {0.0, 2.0, 5.3, 40.0, 700.0, 1e30, inf, nan, -1.0, 0.1};
      const double r = radii[rng() % 10];
      if (q % 7 == 0 && !px.empty()) at = px[rng() % px.size()];  // on a blob (ties)
      if (q % 7 == 1 && !px.empty() && std::isfinite(r)) {
        // Exactly the radius away along an axis, across a cell border: d2 == r^2 or
        // within an ulp of it.
        const Vec2 p = px[rng() % px.size()];
        at = p + (q % 2 ? Vec2(r, 0.0) : Vec2(0.0, -r));
      }
      double d_grid = 0.0, d_scan = 0.0;
      const int g = grid.nearest(at, r, d_grid);
      const int s = grid.nearest_scan(at, r, d_scan);
      ASSERT_EQ(g, s) << "frame " << frame << " query " << q << " r " << r;
      if (g >= 0) {
        ASSERT_TRUE(same_bits(d_grid, d_scan));
      }
      found += g >= 0;
    }
  }
  EXPECT_GT(found, 1000);
}

TEST(StereoIndex, BlobSetIndexFindsTheFirstEqualSet) {
  std::mt19937 rng(11);
  constexpr int kCapacity = 500;
  auto index = BlobSetIndex::create(kCapacity).value();
  std::vector<BlobRefs> keys(kCapacity);
  for (int frame = 0; frame < 50; ++frame) {
    index.clear(frame % 2 == 0 ? kCapacity : kCapacity / 2 + frame);
    for (int i = 0; i < kCapacity; ++i) {
      BlobRefs r;
      for (int c = 0; c < kMaxCameras; ++c)
        r[c] = static_cast<std::int16_t>(rng() % 3 == 0 ? -1 : static_cast<int>(rng() % 4));
      keys[static_cast<std::size_t>(i)] = r;
      int first = -1;
      for (int k = 0; k < i && first < 0; ++k)
        if (keys[static_cast<std::size_t>(k)] == r) first = k;
      const int got = index.find_or_insert(keys.data(), i);
      if (got == BlobSetIndex::kFull) {  // only beyond the frame's stated count
        ASSERT_GE(i, kCapacity / 2 + frame);
        continue;
      }
      ASSERT_EQ(got, first);
    }
  }
}

TEST(StereoIndex, SetupRejectsBadGridsOneLine) {
  const Rig rig = test::paper_rig();
  MultiViewConfig c;
  c.grid_cell_px = 0.0;
  const auto m = MultiViewMerger::create(rig, c);
  ASSERT_FALSE(m);
  EXPECT_EQ(m.error().message.find('\n'), std::string::npos);
  EXPECT_NE(m.error().message.find("grid_cell_px"), std::string::npos);
  EXPECT_FALSE(BlobGrid::create(100, 100, 8.0, 0));
  EXPECT_FALSE(BlobSetIndex::create(0));
  EXPECT_FALSE(BlobUndistorter::create(rig.cameras[0], 0));
}

TEST(StereoIndex, SteadyStateAllocatesNothing) {
  std::mt19937 rng(3);
  test::RingOptions ro;
  const Rig rig = test::humanoid_ring_rig(ro, rng);
  test::SceneOptions so;
  so.hidden = 0.1;
  so.split = 0.05;
  std::vector<std::vector<std::vector<Vec2>>> frames;
  for (int f = 0; f < 8; ++f) frames.push_back(test::humanoid_frame(rig, so, rng));
  test::RigStereoStage stage(rig, test::kIndexedPath);
  stage.run(frames[0]);
  const std::uint64_t before = test::thread_allocation_count();
  for (int f = 0; f < 40; ++f) stage.run(frames[static_cast<std::size_t>(f % 8)]);
  EXPECT_EQ(test::thread_allocation_count() - before, 0u);
  EXPECT_GT(stage.out.size(), 50);
}

}  // namespace
}  // namespace mocap
