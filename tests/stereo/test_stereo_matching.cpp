// Tests of the stereo correspondence stage (StereoTriangulator): the matching rule
// (symmetric epipolar tolerance, cheirality, depth range, reprojection threshold), the
// ambiguity policy (every pair kept, shared blobs flagged), capacity overflow counters,
// sorted-sweep == exhaustive search, and zero heap allocations per frame.
#include <gtest/gtest.h>

#include <algorithm>
#include <random>
#include <set>
#include <tuple>
#include <vector>

#include "stereo/stereo_triangulator.h"
#include "tests/stereo/stereo_test_rig.h"
#include "tests/support/alloc_counter.h"

namespace mocap {
namespace {

StereoTriangulator make_triangulator(const Rig& rig, const StereoConfig& cfg, int a = 0,
                                     int b = 1) {
  auto t = StereoTriangulator::create(rig, cfg, a, b);
  EXPECT_TRUE(t.ok()) << (t.ok() ? "" : t.error().message);
  return std::move(t).value();
}

// Moves pixel px1 of camera 1 by delta_px perpendicular to the epipolar line of px0,
// measured in pixel-scaled undistorted coordinates.
Vec2 shift_off_epipolar_line(const Rig& rig, const StereoGeometry& g, const Vec2& px0,
                             const Vec2& px1, double delta_px) {
  Vec2 xn0, xn1;
  EXPECT_TRUE(undistort_pixel(rig.cameras[0], px0, xn0));
  EXPECT_TRUE(undistort_pixel(rig.cameras[1], px1, xn1));
  const Vec2 s0 = to_scaled(rig.cameras[0], xn0);
  const Vec2 s1 = to_scaled(rig.cameras[1], xn1);
  const Vec3 l1 = g.F_s * Vec3(s0.x(), s0.y(), 1.0);
  const Vec2 normal = l1.head<2>().normalized();
  return normalized_to_pixel(rig.cameras[1], from_scaled(rig.cameras[1], s1 + delta_px * normal));
}

using PairKey = std::tuple<int, int>;
std::set<PairKey> pair_set(const PointList& pts) {
  std::set<PairKey> s;
  for (const Point3& p : pts) s.insert({p.blob_index[0], p.blob_index[1]});
  return s;
}

TEST(StereoMatching, SingleMarkerIsTriangulatedAndNotAmbiguous) {
  const Rig rig = test::paper_rig();
  StereoTriangulator st = make_triangulator(rig, StereoConfig{});
  const Vec3 X(40.0, -30.0, 1050.0);
  Vec2 a, b;
  ASSERT_TRUE(project(rig.cameras[0], X, a) && project(rig.cameras[1], X, b));
  PointList out(64);
  EXPECT_TRUE(st.process(&a, 1, &b, 1, out));
  ASSERT_EQ(out.size(), 1);
  EXPECT_LT((out[0].X_world - X).norm(), 1e-7);
  EXPECT_LT(out[0].reproj_px, 1e-8);
  EXPECT_FALSE(out[0].ambiguous);
  EXPECT_EQ(out[0].blob_index[0], 0);
  EXPECT_EQ(out[0].blob_index[1], 0);
  EXPECT_EQ(out[0].blob_index[2], -1);
  EXPECT_EQ(st.counters().candidates, 1u);
  EXPECT_EQ(st.counters().ambiguous, 0u);
}

TEST(StereoMatching, TwoMarkersOnOneEpipolarPlaneKeepAllFourPairs) {
  const Rig rig = test::paper_rig();
  const Vec3 C0 = rig.cameras[0].center_world(), C1 = rig.cameras[1].center_world();
  const Vec3 X1(-50.0, 20.0, 1000.0);
  // X2 lies in the plane spanned by the baseline and the ray C0 -> X1.
  const Vec3 X2 = C0 + 1.2 * (X1 - C0) + 80.0 * (C1 - C0).normalized();
  Vec2 a[2], b[2];
  ASSERT_TRUE(project(rig.cameras[0], X1, a[0]) && project(rig.cameras[0], X2, a[1]));
  ASSERT_TRUE(project(rig.cameras[1], X1, b[0]) && project(rig.cameras[1], X2, b[1]));
  for (MatchMethod m : {MatchMethod::kSortedSweep, MatchMethod::kExhaustive}) {
    StereoConfig cfg;
    cfg.method = m;
    StereoTriangulator st = make_triangulator(rig, cfg);
    PointList out(64);
    EXPECT_TRUE(st.process(a, 2, b, 2, out));
    ASSERT_EQ(out.size(), 4);  // two true points and two ghosts: nothing silently chosen
    EXPECT_EQ(pair_set(out), (std::set<PairKey>{{0, 0}, {0, 1}, {1, 0}, {1, 1}}));
    for (const Point3& p : out) {
      EXPECT_TRUE(p.ambiguous);
      if (p.blob_index[0] == 0 && p.blob_index[1] == 0) {
        EXPECT_LT((p.X_world - X1).norm(), 1e-6);
      }
      if (p.blob_index[0] == 1 && p.blob_index[1] == 1) {
        EXPECT_LT((p.X_world - X2).norm(), 1e-6);
      }
    }
    EXPECT_EQ(st.counters().ambiguous, 4u);
  }
}

TEST(StereoMatching, OneBlobMatchingTwoCandidatesMarksBothAmbiguous) {
  const Rig rig = test::paper_rig();
  const Vec3 C0 = rig.cameras[0].center_world();
  const Vec3 X1(20.0, 10.0, 950.0);
  const Vec3 X2 = C0 + 1.15 * (X1 - C0);  // same ray of camera 0: one blob there
  Vec2 a, b[3];
  ASSERT_TRUE(project(rig.cameras[0], X1, a));
  ASSERT_TRUE(project(rig.cameras[1], X1, b[0]) && project(rig.cameras[1], X2, b[2]));
  ASSERT_TRUE(project(rig.cameras[1], Vec3(-200.0, -150.0, 1100.0), b[1]));  // unrelated
  StereoTriangulator st = make_triangulator(rig, StereoConfig{});
  PointList out(64);
  EXPECT_TRUE(st.process(&a, 1, b, 3, out));
  ASSERT_EQ(out.size(), 2);
  EXPECT_EQ(pair_set(out), (std::set<PairKey>{{0, 0}, {0, 2}}));
  for (const Point3& p : out) {
    EXPECT_TRUE(p.ambiguous);
    EXPECT_LT((p.X_world - (p.blob_index[1] == 0 ? X1 : X2)).norm(), 1e-6);
  }
}

TEST(StereoMatching, NoMatchOutsideTheEpipolarTolerance) {
  const Rig rig = test::paper_rig();
  StereoConfig cfg;
  cfg.epipolar_tolerance_px = 1.0;
  StereoTriangulator st = make_triangulator(rig, cfg);
  const Vec3 X(-80.0, 60.0, 1200.0);
  Vec2 a, b;
  ASSERT_TRUE(project(rig.cameras[0], X, a) && project(rig.cameras[1], X, b));
  PointList out(64);
  for (double delta : {1.5, -1.5, 3.0, 20.0}) {
    const Vec2 b_off = shift_off_epipolar_line(rig, st.geometry(), a, b, delta);
    EXPECT_TRUE(st.process(&a, 1, &b_off, 1, out));
    EXPECT_EQ(out.size(), 0) << delta;
  }
  EXPECT_EQ(st.counters().pairs_in_tolerance, 0u);
  // Just inside: kept, with the reprojection error the offset implies.
  const Vec2 b_in = shift_off_epipolar_line(rig, st.geometry(), a, b, 0.6);
  EXPECT_TRUE(st.process(&a, 1, &b_in, 1, out));
  ASSERT_EQ(out.size(), 1);
  EXPECT_GT(out[0].reproj_px, 0.1);
  EXPECT_LT(out[0].reproj_px, 0.6);
  EXPECT_NEAR(out[0].epipolar_px, 0.6, 0.1);
}

TEST(StereoMatching, ToleranceIsSymmetricInBothImages) {
  // Camera 1 has twice the focal length: the same geometric offset is twice as many
  // pixels there. A pair within tolerance in image 0 but not in image 1 is rejected.
  Rig rig = test::paper_rig();
  rig.cameras[1].fx = rig.cameras[1].fy = 2 * 1290.0;
  StereoConfig cfg;
  cfg.epipolar_tolerance_px = 1.0;
  StereoTriangulator st = make_triangulator(rig, cfg);
  const Vec3 X(10.0, 5.0, 1000.0);
  Vec2 a, b;
  ASSERT_TRUE(project(rig.cameras[0], X, a) && project(rig.cameras[1], X, b));
  Vec2 xa, xb;
  for (double delta : {1.4, 0.7}) {
    const Vec2 b_off = shift_off_epipolar_line(rig, st.geometry(), a, b, delta);
    ASSERT_TRUE(undistort_pixel(rig.cameras[0], a, xa) &&
                undistort_pixel(rig.cameras[1], b_off, xb));
    double d0 = 0.0, d1 = 0.0;
    epipolar_distances_px(st.geometry(), to_scaled(rig.cameras[0], xa),
                          to_scaled(rig.cameras[1], xb), d0, d1);
    PointList out(8);
    EXPECT_TRUE(st.process(&a, 1, &b_off, 1, out));
    if (delta > 1.0) {
      EXPECT_LT(d0, 1.0);  // within tolerance in image 0 only
      EXPECT_GT(d1, 1.0);
      EXPECT_EQ(out.size(), 0);
    } else {
      EXPECT_LT(std::max(d0, d1), 1.0);
      EXPECT_EQ(out.size(), 1);
    }
  }
}

TEST(StereoMatching, PointBehindTheCamerasIsRejected) {
  const Rig rig = test::paper_rig();
  StereoTriangulator st = make_triangulator(rig, StereoConfig{});
  // Mirror images of a point behind the rig: epipolar-consistent, but the rays meet
  // behind both cameras.
  const Vec3 X(30.0, -20.0, -900.0);
  Vec2 px[2];
  for (int k = 0; k < 2; ++k) {
    const Vec3 Xc = rig.cameras[k].R_cam_world * X + rig.cameras[k].t_cam_world;
    ASSERT_LT(Xc.z(), 0.0);
    px[k] = normalized_to_pixel(rig.cameras[k], Xc.head<2>() / Xc.z());
  }
  PointList out(8);
  EXPECT_TRUE(st.process(&px[0], 1, &px[1], 1, out));
  EXPECT_EQ(out.size(), 0);
  EXPECT_EQ(st.counters().pairs_in_tolerance, 1u);
  EXPECT_EQ(st.counters().rejected_cheirality, 1u);
}

TEST(StereoMatching, DepthRangeAndReprojectionThresholdReject) {
  const Rig rig = test::paper_rig();
  StereoConfig cfg;
  cfg.max_depth_mm = 2000.0;
  cfg.max_reproj_px = 0.05;
  StereoTriangulator st = make_triangulator(rig, cfg);
  PointList out(8);
  Vec2 a, b;
  ASSERT_TRUE(project(rig.cameras[0], Vec3(0, 0, 3000), a) &&
              project(rig.cameras[1], Vec3(0, 0, 3000), b));
  EXPECT_TRUE(st.process(&a, 1, &b, 1, out));
  EXPECT_EQ(out.size(), 0);
  EXPECT_EQ(st.counters().rejected_depth, 1u);
  ASSERT_TRUE(project(rig.cameras[0], Vec3(0, 0, 1000), a) &&
              project(rig.cameras[1], Vec3(0, 0, 1000), b));
  const Vec2 b_off = shift_off_epipolar_line(rig, st.geometry(), a, b, 0.5);
  EXPECT_TRUE(st.process(&a, 1, &b_off, 1, out));
  EXPECT_EQ(out.size(), 0);
  EXPECT_EQ(st.counters().rejected_reproj, 1u);
}

// A frame of n visible markers plus `clutter` random blobs per camera; camera 1's
// order is shuffled.
void make_frame(const Rig& rig, std::mt19937& rng, int n, int clutter, std::vector<Vec2>& a,
                std::vector<Vec2>& b) {
  a.clear();
  b.clear();
  for (int i = 0; i < n; ++i) {
    Vec2 pa, pb;
    test::random_visible_point(rig, rng, pa, pb);
    a.push_back(pa);
    b.push_back(pb);
  }
  std::uniform_real_distribution<double> ux(0.0, 1031.0), uy(0.0, 775.0);
  for (int i = 0; i < clutter; ++i) {
    a.push_back(Vec2(ux(rng), uy(rng)));
    b.push_back(Vec2(ux(rng), uy(rng)));
  }
  std::shuffle(b.begin(), b.end(), rng);
}

void expect_sweep_equals_exhaustive(const Rig& rig, double tol_px, int seed) {
  StereoConfig cfg;
  cfg.epipolar_tolerance_px = tol_px;
  cfg.max_candidates = 100000;
  cfg.min_depth_mm = 1.0;
  cfg.max_depth_mm = 1e6;
  cfg.max_reproj_px = 1e3;
  StereoTriangulator sweep = make_triangulator(rig, cfg);
  cfg.method = MatchMethod::kExhaustive;
  StereoTriangulator full = make_triangulator(rig, cfg);
  std::mt19937 rng(static_cast<unsigned>(seed));
  std::vector<Vec2> a, b;
  PointList out_s(100000), out_f(100000);
  for (int frame = 0; frame < 5; ++frame) {
    make_frame(rig, rng, 150, 50, a, b);
    EXPECT_TRUE(sweep.process(a.data(), static_cast<int>(a.size()), b.data(),
                              static_cast<int>(b.size()), out_s));
    EXPECT_TRUE(full.process(a.data(), static_cast<int>(a.size()), b.data(),
                             static_cast<int>(b.size()), out_f));
    EXPECT_GT(out_f.size(), 150);
    EXPECT_EQ(pair_set(out_s), pair_set(out_f));
  }
  EXPECT_EQ(sweep.counters().pairs_in_tolerance, full.counters().pairs_in_tolerance);
  EXPECT_EQ(sweep.counters().ambiguous, full.counters().ambiguous);
}

TEST(StereoMatching, SortedSweepFindsExactlyTheExhaustivePairs) {
  expect_sweep_equals_exhaustive(test::paper_rig(), 2.0, 1);
  expect_sweep_equals_exhaustive(test::paper_rig(), 8.0, 2);
  expect_sweep_equals_exhaustive(test::paper_rig(), 0.3, 3);
}

TEST(StereoMatching, SortedSweepWithEpipolesInsideTheImages) {
  // Camera 1 ahead of camera 0: epipolar planes fan out around the image centres and
  // blobs near the epipoles need the whole pencil.
  Rig rig;
  rig.cameras.push_back(test::look_at_camera("c0", Vec3(0, 0, 0), Vec3(0, 0, 3000), 1290.0,
                                             {-0.12, 0.09, 0.0, 0.0, 0.0}));
  rig.cameras.push_back(test::look_at_camera("c1", Vec3(20, 10, 300), Vec3(60, -20, 3000), 1290.0,
                                             {-0.1, 0.05, 0.0, 0.0, 0.0}));
  expect_sweep_equals_exhaustive(rig, 2.0, 4);
}

TEST(StereoMatching, CapacityOverflowIsCounted) {
  const Rig rig = test::paper_rig();
  std::mt19937 rng(9);
  std::vector<Vec2> a, b;
  make_frame(rig, rng, 15, 0, a, b);
  StereoConfig cfg;
  cfg.max_points_per_camera = 10;
  StereoTriangulator st = make_triangulator(rig, cfg);
  PointList out(64);
  EXPECT_FALSE(st.process(a.data(), 15, b.data(), 12, out));
  EXPECT_EQ(st.counters().points_overflow[0], 5u);
  EXPECT_EQ(st.counters().points_overflow[1], 2u);
  for (const Point3& p : out) {
    EXPECT_LT(p.blob_index[0], 10);
    EXPECT_LT(p.blob_index[1], 10);
  }

  // Candidate overflow: the 4-candidate ambiguous scene with room for 2.
  const Vec3 C0 = rig.cameras[0].center_world(), C1 = rig.cameras[1].center_world();
  const Vec3 X1(-50.0, 20.0, 1000.0);
  const Vec3 X2 = C0 + 1.2 * (X1 - C0) + 80.0 * (C1 - C0).normalized();
  Vec2 pa[2], pb[2];
  ASSERT_TRUE(project(rig.cameras[0], X1, pa[0]) && project(rig.cameras[0], X2, pa[1]));
  ASSERT_TRUE(project(rig.cameras[1], X1, pb[0]) && project(rig.cameras[1], X2, pb[1]));
  StereoConfig small;
  small.max_candidates = 2;
  StereoTriangulator st2 = make_triangulator(rig, small);
  EXPECT_FALSE(st2.process(pa, 2, pb, 2, out));
  EXPECT_EQ(out.size(), 2);
  EXPECT_EQ(st2.counters().candidate_overflow, 2u);
  EXPECT_EQ(st2.counters().candidates, 4u);
  for (const Point3& p : out) EXPECT_TRUE(p.ambiguous);  // dropped ones still count
  // The output list's own capacity bounds it too.
  StereoTriangulator st3 = make_triangulator(rig, StereoConfig{});
  PointList tiny(3);
  EXPECT_FALSE(st3.process(pa, 2, pb, 2, tiny));
  EXPECT_EQ(tiny.size(), 3);
  EXPECT_EQ(st3.counters().candidate_overflow, 1u);
}

TEST(StereoMatching, BadInputAndUndistortionFailuresAreCounted) {
  const Rig rig = test::paper_rig();
  StereoTriangulator st = make_triangulator(rig, StereoConfig{});
  PointList out(8);
  EXPECT_FALSE(st.process(nullptr, 3, nullptr, 0, out));
  EXPECT_FALSE(st.process(nullptr, 0, nullptr, -1, out));
  EXPECT_EQ(st.counters().bad_input, 2u);
  const Vec2 a(std::nan(""), 10.0), b(500.0, 400.0);
  EXPECT_TRUE(st.process(&a, 1, &b, 1, out));
  EXPECT_EQ(out.size(), 0);
  EXPECT_EQ(st.counters().undistort_failed[0], 1u);
  EXPECT_TRUE(st.process(nullptr, 0, nullptr, 0, out));  // empty frame is fine
}

TEST(StereoMatching, CameraPairOfALargerRigUsesRigIndices) {
  Rig rig = test::paper_rig();
  rig.cameras.push_back(rig.cameras[1]);
  rig.cameras[2].name = "cam2";
  StereoTriangulator st = make_triangulator(rig, StereoConfig{}, 0, 2);
  const Vec3 X(0.0, 0.0, 1000.0);
  Vec2 a, b;
  ASSERT_TRUE(project(rig.cameras[0], X, a) && project(rig.cameras[2], X, b));
  PointList out(8);
  EXPECT_TRUE(st.process(&a, 1, &b, 1, out));
  ASSERT_EQ(out.size(), 1);
  EXPECT_EQ(out[0].blob_index[0], 0);
  EXPECT_EQ(out[0].blob_index[1], -1);
  EXPECT_EQ(out[0].blob_index[2], 0);
}

TEST(StereoMatching, CameraPairsAreEnumeratedLexicographically) {
  std::array<CameraPair, kMaxCameraPairs> pairs{};
  EXPECT_EQ(enumerate_camera_pairs(1, pairs), 0);
  ASSERT_EQ(enumerate_camera_pairs(2, pairs), 1);
  EXPECT_EQ(pairs[0].a, 0);
  EXPECT_EQ(pairs[0].b, 1);
  ASSERT_EQ(enumerate_camera_pairs(3, pairs), 3);
  EXPECT_EQ(pairs[1].a, 0);
  EXPECT_EQ(pairs[1].b, 2);
  EXPECT_EQ(pairs[2].a, 1);
  EXPECT_EQ(pairs[2].b, 2);
  EXPECT_EQ(enumerate_camera_pairs(12, pairs), 66);
  EXPECT_EQ(enumerate_camera_pairs(33, pairs), 496);  // capped at kMaxCameras (32)
  EXPECT_EQ(pairs[kMaxCameraPairs - 1].a, kMaxCameras - 2);
  EXPECT_EQ(pairs[kMaxCameraPairs - 1].b, kMaxCameras - 1);
}

TEST(StereoMatching, SetupErrorsAreOneLine) {
  const Rig rig = test::paper_rig();
  StereoConfig cfg;
  cfg.epipolar_tolerance_px = 0.0;
  auto t = StereoTriangulator::create(rig, cfg);
  ASSERT_FALSE(t.ok());
  EXPECT_EQ(t.error().message, "stereo: epipolar_tolerance_px: must be a positive number");
  cfg = StereoConfig{};
  cfg.max_depth_mm = cfg.min_depth_mm;
  EXPECT_EQ(StereoTriangulator::create(rig, cfg).error().message,
            "stereo: max_depth_mm: must be a number above min_depth_mm");
  EXPECT_EQ(StereoTriangulator::create(rig, StereoConfig{}, 0, 0).error().message,
            "stereo: cameras: pair (0, 0) invalid for a rig of 2 cameras");
  cfg = StereoConfig{};
  cfg.max_points_per_camera = 40000;
  EXPECT_FALSE(StereoTriangulator::create(rig, cfg).ok());
}

TEST(StereoMatching, SteadyStateProcessingAllocatesNothing) {
  const Rig rig = test::paper_rig();
  std::mt19937 rng(12);
  std::vector<std::vector<Vec2>> fa(8), fb(8);
  for (int f = 0; f < 8; ++f) make_frame(rig, rng, 50, 10, fa[f], fb[f]);
  for (MatchMethod m : {MatchMethod::kSortedSweep, MatchMethod::kExhaustive}) {
    StereoConfig cfg;
    cfg.method = m;
    StereoTriangulator st = make_triangulator(rig, cfg);
    PointList out(cfg.max_candidates);
    int total = 0;
    const test::AllocationScope scope;
    for (int rep = 0; rep < 20; ++rep) {
      for (int f = 0; f < 8; ++f) {
        st.process(fa[f].data(), static_cast<int>(fa[f].size()), fb[f].data(),
                   static_cast<int>(fb[f].size()), out);
        total += out.size();
      }
    }
    EXPECT_EQ(scope.count(), 0u);
    EXPECT_GE(total, 20 * 8 * 50);
  }
}

}  // namespace
}  // namespace mocap
