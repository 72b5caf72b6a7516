// Design: what settled blobs (multiview.h) change against the reference merge (every
// candidate a hypothesis). Property test over many random scenes of "the whole robot"
// (3..8 cameras on a ring 2.5-3.5 m around a humanoid volume, 5..150 markers) with the
// design comment's corner cases mixed in: views missing, stray blobs (ghosts through third
// views), split blobs and exact duplicates (rivals with equal view counts), centroids
// shifted by a partly hidden ball (unfit views and pairings), pairs of balls 14-20 mm
// apart whose images merge (shared views). Against the truth (a marker is found when an
// unambiguous point lies within 1 mm; a stray point lies 5 mm from every marker), the
// merge with settled blobs, pair by pair as FrameProcessor runs it:
//  - finds more markers than the reference, and loses at most 0.5 % of the reference's;
//  - reports at most 10 % more strays;
//  - makes fewer than half the reference's hypotheses; the corner cases occur.
// The reference switch of the environment (MOCAP_MULTIVIEW_REFERENCE=1) turns it off.
#include <gtest/gtest.h>

#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <random>

#include "tests/stereo/humanoid_scene.h"
#include "tests/stereo/rig_stereo_stage.h"

namespace mocap {
namespace {

// The reported point nearest to X (within radius_mm), or -1.
int settled_nearest_reported(const PointList& points, const Vec3& X, double radius_mm) {
  int best = -1;
  double best_d = radius_mm;
  for (int i = 0; i < points.size(); ++i) {
    const double d = (points[i].X_world - X).norm();
    if (points[i].reported && d <= best_d) {
      best_d = d;
      best = i;
    }
  }
  return best;
}

// Reported points farther than 5 mm from every marker.
int settled_strays(const PointList& points, const std::vector<Vec3>& markers) {
  int n = 0;
  for (const Point3& p : points) {
    if (!p.reported) continue;
    bool near = false;
    for (const Vec3& X : markers) near = near || (p.X_world - X).norm() <= 5.0;
    n += !near;
  }
  return n;
}

TEST(MultiViewSettled, FindsEveryMarkerTheReferenceFindsOnRandomScenesWithCornerCases) {
  std::mt19937 rng(20261207);
  std::uint64_t reference_found = 0, both_found = 0, same_position = 0, settled_only = 0;
  int reference_strays = 0, strays = 0, frames = 0;
  std::uint64_t skipped = 0, hypotheses_reference = 0;
  MultiViewCounters total;
  for (int s = 0; s < 240; ++s) {
    const int cameras = 3 + s % 6;
    const Rig rig = test::random_ring_rig(cameras, rng);
    test::SceneOptions so = test::random_scene(150, 8, 0.3, rng);
    std::uniform_real_distribution<double> u01(0.0, 1.0);
    so.split = s % 4 == 0 ? 0.0 : 0.08 * u01(rng);
    so.duplicate = s % 5 == 1 ? 0.03 : 0.0;
    so.shifted = s % 3 == 0 ? 0.0 : 0.15 * u01(rng);
    so.twin = s % 2 == 0 ? 0.2 * u01(rng) : 0.0;
    so.facing_deg = s % 2 ? 90.0 : 180.0;
    test::RigStereoStage settled(rig, test::kIndexedPath), reference(rig, test::kReferencePath);
    for (int f = 0; f < 2; ++f) {
      std::vector<Vec3> markers;
      const auto px = test::humanoid_frame(rig, so, rng, &markers);
      settled.run(px);
      reference.run(px);
      SCOPED_TRACE(::testing::Message() << "scene " << s << " frame " << f << ", " << cameras
                                        << " cameras, " << so.markers << " markers");
      for (const Vec3& X : markers) {
        const int r = settled_nearest_reported(reference.out, X, 1.0);
        const int k = settled_nearest_reported(settled.out, X, 1.0);
        if (r >= 0) {
          ++reference_found;
          if (k >= 0) {
            ++both_found;
            same_position += (settled.out[k].X_world - reference.out[r].X_world).norm() < 1e-9;
          }
        } else if (k >= 0) {
          ++settled_only;
        }
      }
      reference_strays += settled_strays(reference.out, markers);
      strays += settled_strays(settled.out, markers);
      ++frames;
    }
    for (std::size_t k = 0; k < settled.pairs.size(); ++k)
      skipped += reference.pairs[k].counters().candidates - settled.pairs[k].counters().candidates;
    hypotheses_reference += reference.merger.counters().hypotheses;
    const MultiViewCounters& a = settled.merger.counters();
    total.hypotheses += a.hypotheses;
    total.unfit_pairings += a.unfit_pairings;
    total.unfit_views += a.unfit_views;
    total.shared_views_split += a.shared_views_split;
    total.ghosts_rejected += a.ghosts_rejected;
    total.ambiguous += a.ambiguous;
    EXPECT_EQ(reference.merger.counters().settled, 0u);
  }
  EXPECT_EQ(frames, 480);
  std::printf(
      "settled: markers the reference reports %llu, also settled %llu (same position %llu), "
      "settled only %llu; strays %d (reference %d); candidates skipped %llu of %llu; "
      "ghosts %llu, ambiguous %llu, unfit pairings %llu, splits %llu\n",
      static_cast<unsigned long long>(reference_found), static_cast<unsigned long long>(both_found),
      static_cast<unsigned long long>(same_position), static_cast<unsigned long long>(settled_only),
      strays, reference_strays, static_cast<unsigned long long>(skipped),
      static_cast<unsigned long long>(hypotheses_reference),
      static_cast<unsigned long long>(total.ghosts_rejected),
      static_cast<unsigned long long>(total.ambiguous),
      static_cast<unsigned long long>(total.unfit_pairings),
      static_cast<unsigned long long>(total.shared_views_split));
  // Settling finds more markers than the reference: the equal-view rivals it spares made
  // true points ambiguous there...
  EXPECT_GT(both_found + settled_only, reference_found);
  // ...and loses few of the reference's: twins whose merged images settled with another
  // point (0.46 % here; most are still reported 1-3 mm off, with the merged view).
  EXPECT_GE(both_found, reference_found - reference_found / 200);
  EXPECT_LE(strays, reference_strays + reference_strays / 10);
  // Settling does the work: most candidates are no hypotheses.
  EXPECT_GT(skipped, hypotheses_reference / 2);
  EXPECT_LT(total.hypotheses, hypotheses_reference / 2);
  // ...and the scenes reach every corner case of the design comment.
  EXPECT_GT(total.unfit_pairings, 0u);
  EXPECT_GT(total.unfit_views, 0u);
  EXPECT_GT(total.shared_views_split, 0u);
  EXPECT_GT(total.ghosts_rejected, 0u);
  EXPECT_GT(total.ambiguous, 0u);
}

TEST(MultiViewSettled, EnvironmentSwitchRunsTheReference) {
  std::mt19937 rng(5);
  test::RingOptions ro;
  const Rig rig = test::humanoid_ring_rig(ro, rng);
  test::SceneOptions so;
  const auto px = test::humanoid_frame(rig, so, rng);
  test::RigStereoStage on(rig, test::kIndexedPath), reference(rig, test::kReferencePath);
  ::setenv("MOCAP_MULTIVIEW_REFERENCE", "1", 1);
  test::RigStereoStage off(rig, test::kIndexedPath);
  ::unsetenv("MOCAP_MULTIVIEW_REFERENCE");
  on.run(px);
  off.run(px);
  reference.run(px);
  std::uint64_t on_skipped = 0, off_skipped = 0;
  for (const StereoTriangulator& st : on.pairs) on_skipped += st.counters().settled_blobs;
  for (const StereoTriangulator& st : off.pairs) off_skipped += st.counters().settled_blobs;
  EXPECT_GT(on_skipped, 0u);
  EXPECT_EQ(off_skipped, 0u);
  ASSERT_EQ(off.out.size(), reference.out.size());
  for (int i = 0; i < off.out.size(); ++i) {
    EXPECT_EQ(off.out[i].X_world, reference.out[i].X_world);
    EXPECT_EQ(off.out[i].blob_index, reference.out[i].blob_index);
  }
}

}  // namespace
}  // namespace mocap
