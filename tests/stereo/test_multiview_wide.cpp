// Design: the stereo stage on rigs of more than 8 cameras (kMaxCameras is 32): a ring
// of 12 and one of 16 cameras around a humanoid volume, markers on the body's surface
// (each seen by the cameras in front of it; no two markers' images within 12 px), 0.1 px
// noise, no strays. The pairwise
// triangulators and the N-view merge must give every marker seen by three or more
// cameras as one point made of exactly its true blobs in every camera that saw it
// (cameras 8..15 included: camera masks above bit 7), close to the true position, and
// no point mixing blobs of different markers.
#include <gtest/gtest.h>

#include <random>
#include <vector>

#include "tests/stereo/humanoid_scene.h"
#include "tests/stereo/rig_stereo_stage.h"

namespace mocap {
namespace {

struct WideRingFrame {
  std::vector<Vec3> X;                  // true markers
  std::vector<std::vector<Vec2>> px;    // per camera: blobs
  std::vector<std::vector<int>> owner;  // per camera, per blob: its marker
  std::vector<BlobRefs> truth;          // per marker: its blob in each camera that saw it
};

// Markers whose images (seen or hidden) lie at least 12 px apart in every camera, so that
// a hidden marker's projection never lands on another marker's blob (a scene ambiguity,
// not the merge's).
WideRingFrame wide_ring_frame(const Rig& rig, int markers, std::mt19937& rng) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::normal_distribution<double> noise(0.0, 0.1);
  const std::size_t nc = rig.cameras.size();
  WideRingFrame f;
  f.px.resize(nc);
  f.owner.resize(nc);
  std::vector<std::vector<Vec2>> images(nc);  // every marker's projection per camera
  while (static_cast<int>(f.X.size()) < markers) {
    const Vec3 X(300.0 * u(rng), 900.0 * u(rng), 300.0 * u(rng));
    Vec3 normal(u(rng), 0.2 * u(rng), u(rng));  // mostly horizontal: seen around the ring
    normal.normalize();
    std::vector<Vec2> at(nc);
    bool clear = true;
    for (std::size_t c = 0; c < nc && clear; ++c) {
      clear = project(rig.cameras[c], X, at[c]) && test::in_image(rig.cameras[c], at[c]);
      for (const Vec2& q : images[c]) clear = clear && (q - at[c]).norm() > 12.0;
    }
    if (!clear) continue;
    BlobRefs refs;
    for (std::size_t c = 0; c < nc; ++c) {
      images[c].push_back(at[c]);
      if (normal.dot((rig.cameras[c].center_world() - X).normalized()) < 0.0) continue;
      refs.set(c, static_cast<int>(f.px[c].size()));
      f.px[c].push_back(at[c] + Vec2(noise(rng), noise(rng)));
      f.owner[c].push_back(static_cast<int>(f.X.size()));
    }
    f.X.push_back(X);
    f.truth.push_back(refs);
  }
  return f;
}

void expect_every_marker_whole(int cameras, unsigned seed) {
  std::mt19937 rng(seed);
  test::RingOptions ro;
  ro.cameras = cameras;
  const Rig rig = test::humanoid_ring_rig(ro, rng);
  test::RigStereoStage stage(rig, test::kIndexedPath);
  CameraMask cameras_used = 0;
  int whole = 0, expected = 0;
  for (int frame = 0; frame < 3; ++frame) {
    const WideRingFrame f = wide_ring_frame(rig, 24, rng);
    stage.run(f.px);
    std::vector<int> found(f.X.size(), 0);
    for (const Point3& p : stage.out) {
      if (!p.reported) continue;
      int marker = -1;
      bool mixed = false;
      p.blob_index.for_each([&](int c, int b) {
        const int m = f.owner[static_cast<std::size_t>(c)][static_cast<std::size_t>(b)];
        mixed = mixed || (marker >= 0 && m != marker);
        marker = m;
      });
      ASSERT_FALSE(mixed) << "a point of blobs of different markers, cameras " << std::hex
                          << p.blob_index.mask();
      ASSERT_GE(marker, 0);
      const BlobRefs& truth = f.truth[static_cast<std::size_t>(marker)];
      if (truth.count() < 3) continue;
      EXPECT_EQ(p.blob_index, truth) << "marker " << marker << ": views " << std::hex
                                     << p.blob_index.mask() << ", seen by " << truth.mask();
      EXPECT_EQ(p.blob_index.count(), truth.count());
      EXPECT_LT((p.X_world - f.X[static_cast<std::size_t>(marker)]).norm(), 1.0);
      cameras_used |= p.blob_index.mask();
      ++found[static_cast<std::size_t>(marker)];
    }
    for (std::size_t m = 0; m < f.X.size(); ++m) {
      if (f.truth[m].count() < 3) continue;
      ++expected;
      EXPECT_EQ(found[m], 1) << "marker " << m << " seen by " << f.truth[m].count();
      whole += found[m] == 1;
    }
  }
  EXPECT_EQ(whole, expected);
  EXPECT_GT(expected, 30);
  // Every camera of the ring, those above 7 included, took part in some point.
  const CameraMask all = (CameraMask{1} << cameras) - 1;
  EXPECT_EQ(cameras_used, all) << std::hex << cameras_used;
}

TEST(MultiViewWide, TwelveCamerasGiveEveryMarkerWithAllItsViews) {
  expect_every_marker_whole(12, 21);
}

TEST(MultiViewWide, SixteenCamerasGiveEveryMarkerWithAllItsViews) {
  expect_every_marker_whole(16, 5);
}

}  // namespace
}  // namespace mocap
