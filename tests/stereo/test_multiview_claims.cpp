// Design: the merge's claims (multiview.h, multiview_claims.cpp) change nothing the merge
// reports. Property test over many random scenes of "the whole robot" (3..8 cameras on a
// ring 2.5-3.5 m around a humanoid volume, 5..150 markers) with the design comment's
// corner cases mixed in: views missing, stray blobs (ghosts through third views), split
// blobs and exact duplicates (rivals with equal view counts), centroids shifted by a
// partly hidden ball (unfit views and pairings), pairs of balls 14-20 mm apart whose
// images merge (shared views). The merge with claims and the reference (every hypothesis
// extended) must give bit for bit the same points in the same order (X_world, errors,
// blob per camera, ambiguous and reported flags) and every counter but `claimed`; the
// claims must spare a large share of the hypotheses, and the corner cases must occur.
// The reference switch of the environment (MOCAP_MULTIVIEW_REFERENCE=1) turns claims off.
#include <gtest/gtest.h>

#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <random>

#include "tests/stereo/humanoid_scene.h"
#include "tests/stereo/rig_stereo_stage.h"

namespace mocap {
namespace {

bool claims_same_bits(double a, double b) { return std::memcmp(&a, &b, sizeof(a)) == 0; }

bool claims_identical(const Point3& a, const Point3& b) {
  return claims_same_bits(a.X_world.x(), b.X_world.x()) &&
         claims_same_bits(a.X_world.y(), b.X_world.y()) &&
         claims_same_bits(a.X_world.z(), b.X_world.z()) &&
         claims_same_bits(a.reproj_px, b.reproj_px) &&
         claims_same_bits(a.epipolar_px, b.epipolar_px) && a.blob_index == b.blob_index &&
         a.ambiguous == b.ambiguous && a.reported == b.reported;
}

TEST(MultiViewClaims, SameResultAsTheReferenceOnRandomScenesWithCornerCases) {
  std::mt19937 rng(20261205);
  MultiViewCounters total;
  int frames = 0;
  for (int s = 0; s < 300; ++s) {
    test::RingOptions ro;
    ro.cameras = 3 + s % 6;
    ro.radius_mm = 2500.0 + 1000.0 * std::uniform_real_distribution<double>(0.0, 1.0)(rng);
    ro.jitter_deg = 15.0;
    const Rig rig = test::humanoid_ring_rig(ro, rng);
    test::SceneOptions so;
    std::uniform_real_distribution<double> u01(0.0, 1.0);
    so.markers = 5 + static_cast<int>(rng() % 146);
    so.strays = static_cast<int>(rng() % 9);
    so.hidden = 0.3 * u01(rng);
    so.split = s % 4 == 0 ? 0.0 : 0.08 * u01(rng);
    so.duplicate = s % 5 == 1 ? 0.03 : 0.0;
    so.shifted = s % 3 == 0 ? 0.0 : 0.15 * u01(rng);
    so.twin = s % 2 == 0 ? 0.2 * u01(rng) : 0.0;
    so.facing_deg = s % 2 ? 90.0 : 180.0;
    test::RigStereoStage fast(rig, test::kIndexedPath), reference(rig, test::kReferencePath);
    for (int f = 0; f < 2; ++f) {
      const auto px = test::humanoid_frame(rig, so, rng);
      fast.run(px);
      reference.run(px);
      SCOPED_TRACE(::testing::Message() << "scene " << s << " frame " << f << ", " << ro.cameras
                                        << " cameras, " << so.markers << " markers");
      ASSERT_EQ(fast.out.size(), reference.out.size());
      for (int i = 0; i < fast.out.size(); ++i)
        ASSERT_TRUE(claims_identical(fast.out[i], reference.out[i])) << "point " << i;
      ++frames;
    }
    MultiViewCounters a = fast.merger.counters(), b = reference.merger.counters();
    EXPECT_EQ(b.claimed, 0u);
    total.claimed += a.claimed;
    total.hypotheses += a.hypotheses;
    total.unfit_pairings += a.unfit_pairings;
    total.unfit_views += a.unfit_views;
    total.shared_views_split += a.shared_views_split;
    total.ghosts_rejected += a.ghosts_rejected;
    total.ambiguous += a.ambiguous;
    total.merged += a.merged;
    a.claimed = 0;
    ASSERT_EQ(std::memcmp(&a, &b, sizeof(a)), 0) << "counters, scene " << s;
  }
  EXPECT_EQ(frames, 600);
  // The claims do the work: a large share of the hypotheses is not extended...
  EXPECT_GT(total.claimed, total.hypotheses / 4);
  // ...and the scenes reach every corner case of the design comment.
  EXPECT_GT(total.unfit_pairings, 0u);
  EXPECT_GT(total.unfit_views, 0u);
  EXPECT_GT(total.shared_views_split, 0u);
  EXPECT_GT(total.ghosts_rejected, 0u);
  EXPECT_GT(total.ambiguous, 0u);
  std::printf(
      "claims: %llu of %llu hypotheses; merged %llu, ghosts %llu, ambiguous %llu, "
      "unfit pairings %llu, splits %llu\n",
      static_cast<unsigned long long>(total.claimed),
      static_cast<unsigned long long>(total.hypotheses),
      static_cast<unsigned long long>(total.merged),
      static_cast<unsigned long long>(total.ghosts_rejected),
      static_cast<unsigned long long>(total.ambiguous),
      static_cast<unsigned long long>(total.unfit_pairings),
      static_cast<unsigned long long>(total.shared_views_split));
}

TEST(MultiViewClaims, EnvironmentSwitchRunsTheReference) {
  std::mt19937 rng(5);
  test::RingOptions ro;
  const Rig rig = test::humanoid_ring_rig(ro, rng);
  test::SceneOptions so;
  const auto px = test::humanoid_frame(rig, so, rng);
  test::RigStereoStage on(rig, test::kIndexedPath);
  ::setenv("MOCAP_MULTIVIEW_REFERENCE", "1", 1);
  test::RigStereoStage off(rig, test::kIndexedPath);
  ::unsetenv("MOCAP_MULTIVIEW_REFERENCE");
  on.run(px);
  off.run(px);
  EXPECT_GT(on.merger.counters().claimed, 0u);
  EXPECT_EQ(off.merger.counters().claimed, 0u);
  ASSERT_EQ(on.out.size(), off.out.size());
  for (int i = 0; i < on.out.size(); ++i) EXPECT_TRUE(claims_identical(on.out[i], off.out[i]));
}

}  // namespace
}  // namespace mocap
