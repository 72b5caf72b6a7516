// Design: N-view correspondence (stereo/multiview.h) on a 4-camera ring with lenses of
// different focal lengths and distortions, 0.1 px centroid noise, 25 % of the views
// hidden at random (occlusion) and stray blobs in every image. The pairwise stereo
// triangulators propose; the merger must give every point seen by 3 or more cameras
// with exactly its true blobs, never a reported point made of blobs of different
// markers (a ghost), more accurate points than any pair alone, and, with two cameras,
// the pair's candidates unchanged; two balls on one ray of a camera are both reported
// when a diameter apart. process() allocates nothing.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <random>
#include <vector>

#include "stereo/multiview.h"
#include "stereo/stereo_triangulator.h"
#include "tests/stereo/stereo_test_rig.h"
#include "tests/support/alloc_counter.h"

namespace mocap {
namespace {

struct Frame {
  std::vector<Vec3> X;                  // true points
  std::vector<std::vector<Vec2>> px;    // per camera: blobs (shuffled)
  std::vector<std::vector<int>> owner;  // per camera, per blob: true point or -1
  std::vector<int> seen_by;             // per point: cameras with its blob
};

Frame make_frame(const Rig& rig, std::mt19937& rng, int points, int strays) {
  std::uniform_real_distribution<double> ux(-250.0, 250.0), uz(800.0, 1200.0), u01(0.0, 1.0);
  std::normal_distribution<double> noise(0.0, 0.1);
  const std::size_t nc = rig.cameras.size();
  Frame f;
  f.px.resize(nc);
  f.owner.resize(nc);
  for (int i = 0; i < points; ++i) {
    const Vec3 X(ux(rng), ux(rng), uz(rng));
    f.X.push_back(X);
    f.seen_by.push_back(0);
    for (std::size_t c = 0; c < nc; ++c) {
      Vec2 p;
      if (!project(rig.cameras[c], X, p) || !test::in_image(rig.cameras[c], p)) continue;
      if (u01(rng) < 0.25) continue;  // hidden from this camera
      f.px[c].push_back(p + Vec2(noise(rng), noise(rng)));
      f.owner[c].push_back(i);
      ++f.seen_by.back();
    }
  }
  for (std::size_t c = 0; c < nc; ++c) {
    for (int s = 0; s < strays; ++s) {
      f.px[c].push_back(Vec2(u01(rng) * 1031.0, u01(rng) * 775.0));
      f.owner[c].push_back(-1);
    }
    std::vector<std::size_t> perm(f.px[c].size());
    for (std::size_t k = 0; k < perm.size(); ++k) perm[k] = k;
    std::shuffle(perm.begin(), perm.end(), rng);
    std::vector<Vec2> px;
    std::vector<int> ow;
    for (std::size_t k : perm) {
      px.push_back(f.px[c][k]);
      ow.push_back(f.owner[c][k]);
    }
    f.px[c] = px;
    f.owner[c] = ow;
  }
  return f;
}

// The true point that owns at least two of p's blobs and all but at most one (a blob
// of another marker that lies within the gate of this one's image: the two overlap
// there), or -1: a point made of blobs of different markers or of strays.
int truth_of(const Point3& p, const Frame& f) {
  int views = 0, best = -1, best_count = 0;
  for (std::size_t c = 0; c < f.px.size(); ++c) {
    const int j = p.blob_index[c];
    if (j < 0) continue;
    ++views;
    const int o = f.owner[c][static_cast<std::size_t>(j)];
    if (o < 0) continue;
    int count = 0;
    for (std::size_t k = 0; k < f.px.size(); ++k)
      count += p.blob_index[k] >= 0 && f.owner[k][static_cast<std::size_t>(p.blob_index[k])] == o;
    if (count > best_count) {
      best_count = count;
      best = o;
    }
  }
  return best_count >= 2 && best_count >= views - 1 ? best : -1;
}

// A reported point that is not a marker but uses a blob of a marker seen by 3 or more
// cameras: a ghost that the third view should have rejected.
bool steals_a_confirmed_blob(const Point3& p, const Frame& f) {
  for (std::size_t c = 0; c < f.px.size(); ++c) {
    const int j = p.blob_index[c];
    if (j < 0) continue;
    const int o = f.owner[c][static_cast<std::size_t>(j)];
    if (o >= 0 && f.seen_by[static_cast<std::size_t>(o)] >= 3) return true;
  }
  return false;
}

struct Stage {
  std::vector<StereoTriangulator> pairs;
  std::vector<PointList> pair_out;
  MultiViewMerger merger;
  PointList out{4096};

  explicit Stage(const Rig& rig, const MultiViewConfig& config = MultiViewConfig{})
      : merger(MultiViewMerger::create(rig, config).value()) {
    std::array<CameraPair, kMaxCameraPairs> cp{};
    const int np = enumerate_camera_pairs(static_cast<int>(rig.cameras.size()), cp);
    for (int k = 0; k < np; ++k) {
      pairs.push_back(StereoTriangulator::create(rig, StereoConfig{},
                                                 cp[static_cast<std::size_t>(k)].a,
                                                 cp[static_cast<std::size_t>(k)].b)
                          .value());
      pair_out.emplace_back(1024);
    }
  }
  void run(const Frame& f) {
    const Vec2* px[kMaxCameras] = {};
    int n[kMaxCameras] = {};
    for (std::size_t c = 0; c < f.px.size(); ++c) {
      px[c] = f.px[c].data();
      n[c] = static_cast<int>(f.px[c].size());
    }
    const PointList* lists[kMaxCameraPairs] = {};
    for (std::size_t k = 0; k < pairs.size(); ++k) {
      const int a = pairs[k].camera_a(), b = pairs[k].camera_b();
      pairs[k].process(px[a], n[a], px[b], n[b], pair_out[k]);
      lists[k] = &pair_out[k];
    }
    merger.process(px, n, lists, static_cast<int>(pairs.size()), out);
  }
};

TEST(MultiView, FourCamerasFindEveryPointSeenThreeTimesWithoutGhosts) {
  const Rig rig = test::ring_rig();
  Stage st(rig);
  std::mt19937 rng(11);
  int expected = 0, found = 0, ghosts = 0, spurious = 0;
  double se_merged = 0.0, se_pair = 0.0;
  int n_merged = 0, n_pair = 0;
  for (int frame = 0; frame < 40; ++frame) {
    const Frame f = make_frame(rig, rng, 30, 3);
    st.run(f);
    std::vector<int> reported_for(f.X.size(), 0);
    for (const Point3& p : st.out) {
      if (!p.reported) continue;
      const int id = truth_of(p, f);
      if (id < 0) {
        ++spurious;
        if (steals_a_confirmed_blob(p, f)) ++ghosts;
        if (std::getenv("MULTIVIEW_VERBOSE")) {
          std::fprintf(stderr, "ghost:");
          for (std::size_t c = 0; c < f.px.size(); ++c) {
            const int j = p.blob_index[c];
            std::fprintf(stderr, " cam%zu=%d", c,
                         j < 0 ? -9 : f.owner[c][static_cast<std::size_t>(j)]);
          }
          std::fprintf(stderr, " reproj %.2f\n", p.reproj_px);
        }
        continue;
      }
      ++reported_for[static_cast<std::size_t>(id)];
      int views = 0;
      for (std::int16_t j : p.blob_index.indices()) views += j >= 0 ? 1 : 0;
      if (views >= 3) {
        se_merged += (p.X_world - f.X[static_cast<std::size_t>(id)]).squaredNorm();
        ++n_merged;
      }
    }
    for (const PointList& l : st.pair_out)  // the pairs' own (2-view) accuracy
      for (const Point3& p : l) {
        const int id = truth_of(p, f);
        if (id < 0 || f.seen_by[static_cast<std::size_t>(id)] < 3) continue;
        se_pair += (p.X_world - f.X[static_cast<std::size_t>(id)]).squaredNorm();
        ++n_pair;
      }
    for (std::size_t i = 0; i < f.X.size(); ++i) {
      EXPECT_LE(reported_for[i], 1) << "point " << i << " reported twice";
      if (f.seen_by[i] < 3) continue;
      ++expected;
      found += reported_for[i] == 1 ? 1 : 0;
    }
  }
  EXPECT_EQ(ghosts, 0);
  // Points made of strays (and of blobs of markers only two cameras see) cannot be told
  // from a marker seen by two cameras: they are reported like one, and left to the
  // identification, which rejects what fits no target. 3 strays per image here.
  EXPECT_LE(spurious, 40) << "about one per frame at most";
  EXPECT_GE(found, static_cast<int>(0.99 * expected)) << found << " of " << expected;
  ASSERT_GT(n_merged, 0);
  const double rmse_merged = std::sqrt(se_merged / n_merged);
  const double rmse_pair = std::sqrt(se_pair / n_pair);
  EXPECT_LT(rmse_merged, 0.8 * rmse_pair) << rmse_merged << " mm against pairs " << rmse_pair;
  if (std::getenv("MULTIVIEW_VERBOSE"))
    std::fprintf(stderr, "found %d of %d, spurious %d, rmse %.4f mm (pairs %.4f mm)\n", found,
                 expected, spurious, rmse_merged, rmse_pair);
  EXPECT_GT(st.merger.counters().views_added, 0u);
  // The same marker from later pairs: their candidates of two settled blobs are none.
  EXPECT_GT(st.merger.counters().settled, 0u);
}

TEST(MultiView, ProcessAllocatesNothing) {
  const Rig rig = test::ring_rig();
  Stage st(rig);
  std::mt19937 rng(5);
  Frame f = make_frame(rig, rng, 20, 0);
  st.run(f);  // warm
  {
    test::AllocationScope scope;
    for (int k = 0; k < 5; ++k) st.run(f);
    EXPECT_EQ(scope.count(), 0u);
  }
  EXPECT_EQ(st.merger.counters().hypothesis_overflow + st.merger.counters().point_overflow, 0u);
}

TEST(MultiView, TwoCamerasPassThePairUnchanged) {
  const Rig rig = test::paper_rig();
  Stage st(rig);
  std::mt19937 rng(3);
  for (int frame = 0; frame < 10; ++frame) {
    const Frame f = make_frame(rig, rng, 25, 4);
    st.run(f);
    ASSERT_EQ(st.out.size(), st.pair_out[0].size());
    for (int i = 0; i < st.out.size(); ++i) {
      EXPECT_EQ(st.out[i].X_world, st.pair_out[0][i].X_world);
      EXPECT_EQ(st.out[i].blob_index, st.pair_out[0][i].blob_index);
      EXPECT_EQ(st.out[i].ambiguous, st.pair_out[0][i].ambiguous);
    }
  }
}

// Two balls on one ray of camera 2 (the far one hidden behind the near one there: one
// blob), each seen on its own by cameras 0, 1 and 3. Both points take camera 2's blob;
// they are a ball's diameter or more apart, so the second gives the blob up and both are
// reported. Balls closer than a diameter cannot both exist: they stay exclusive rivals.
struct OneRayFrame {
  std::vector<std::vector<Vec2>> px;
  Vec3 near, far;
};

OneRayFrame one_ray_frame(const Rig& rig, double apart_mm) {
  OneRayFrame f;
  f.near = Vec3(20.0, -10.0, 1000.0);
  const Vec3 C2 = rig.cameras[2].center_world();
  f.far = f.near + (f.near - C2).normalized() * apart_mm;
  f.px.resize(rig.cameras.size());
  for (std::size_t c = 0; c < rig.cameras.size(); ++c) {
    Vec2 a, b;
    EXPECT_TRUE(project(rig.cameras[c], f.near, a) && project(rig.cameras[c], f.far, b));
    f.px[c].push_back(a);
    if (c != 2) f.px[c].push_back(b);  // camera 2: the far ball is behind the near one
  }
  return f;
}

int reported_near(const PointList& out, const Vec3& X) {
  int n = 0;
  for (const Point3& p : out) n += p.reported && (p.X_world - X).norm() < 0.01;
  return n;
}

TEST(MultiView, TwoBallsOnOneRayOfACameraAreBothReported) {
  const Rig rig = test::ring_rig();
  MultiViewConfig config;
  config.marker_radius_mm = 7.0;
  Stage st(rig, config);
  const OneRayFrame f = one_ray_frame(rig, 150.0);
  Frame frame;
  frame.px = f.px;
  st.run(frame);
  EXPECT_EQ(reported_near(st.out, f.near), 1);
  EXPECT_EQ(reported_near(st.out, f.far), 1);
  int with_cam2 = 0;
  for (const Point3& p : st.out) {
    EXPECT_FALSE(p.ambiguous);
    with_cam2 += p.blob_index[2] >= 0;
  }
  EXPECT_EQ(with_cam2, 1) << "camera 2's one blob belongs to one point";
  EXPECT_EQ(st.merger.counters().shared_views_split, 1u);
}

// A marker seen whole by cameras 1 and 2 and only in part by camera 3 (its blob there
// 6 px off its projection, within the ball's image), and a ghost: a camera-1 blob of
// something else on the epipolar line of the marker's camera-2 blob, with no image in any
// other camera. Both stand on two views, and the ghost fits exactly. The marker, which a
// third camera partly confirms, is accepted first; the pairing of its camera-2 blob with
// its partial view is then the marker again, not a rival a few millimetres off.
TEST(MultiView, PartlySeenMarkerGoesBeforeAnExactGhost) {
  const Rig rig = test::ring_rig();
  MultiViewConfig config;
  config.marker_radius_mm = 7.0;
  Stage st(rig, config);
  const Vec3 X(20.0, -10.0, 1000.0);
  const Vec3 C2 = rig.cameras[2].center_world();
  const Vec3 ghost = C2 + (X - C2) * (1.0 + 200.0 / (X - C2).norm());  // on camera 2's ray
  Frame frame;
  frame.px.resize(4);  // camera 0 sees nothing
  Vec2 a1, a2, a3, g1;
  ASSERT_TRUE(project(rig.cameras[1], X, a1) && project(rig.cameras[2], X, a2) &&
              project(rig.cameras[3], X, a3) && project(rig.cameras[1], ghost, g1));
  frame.px[1] = {a1 + Vec2(0.05, 0.0), g1};
  frame.px[2] = {a2};
  frame.px[3] = {a3 + Vec2(6.0, 0.0)};
  st.run(frame);
  int marker = 0, rivals = 0;
  for (const Point3& p : st.out) {
    const double d = (p.X_world - X).norm();
    marker += d < 0.5;
    rivals += d >= 0.5 && d < 20.0;
  }
  EXPECT_EQ(marker, 1);
  EXPECT_EQ(rivals, 0);
  EXPECT_GE(st.merger.counters().unfit_pairings, 1u);
}

TEST(MultiView, BallsCloserThanADiameterStayRivals) {
  const Rig rig = test::ring_rig();
  MultiViewConfig config;
  config.marker_radius_mm = 7.0;
  Stage st(rig, config);
  const OneRayFrame f = one_ray_frame(rig, 10.0);  // two 14 mm balls would overlap
  Frame frame;
  frame.px = f.px;
  st.run(frame);
  EXPECT_EQ(st.merger.counters().shared_views_split, 0u);
  EXPECT_LE(reported_near(st.out, f.near) + reported_near(st.out, f.far), 1);
}

TEST(MultiView, SetupErrors) {
  Rig one = test::paper_rig();
  one.cameras.resize(1);
  auto e = MultiViewMerger::create(one, MultiViewConfig{});
  ASSERT_FALSE(e.ok());
  EXPECT_EQ(e.error().message, "multiview: 1 cameras, expected 2..32");
  MultiViewConfig bad;
  bad.gate_px = 0.0;
  EXPECT_FALSE(MultiViewMerger::create(test::paper_rig(), bad).ok());
  MultiViewConfig negative;
  negative.marker_radius_mm = -1.0;
  EXPECT_FALSE(MultiViewMerger::create(test::paper_rig(), negative).ok());
}

}  // namespace
}  // namespace mocap
