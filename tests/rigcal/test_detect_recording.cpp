// detect_recording (rigcal/rig_calibrator.h) on a small recording drawn by
// tests/detect/synth.h (not the simulator): a wand whose first ball has a notch cut by
// its rod (less round than a whole ball) and an oval stray. The notched ball is kept,
// as a labelled wand ball whose centre comes from its edge: it lands on the true centre,
// where its intensity centroid does not. The stray is left out, and so is the same notched
// ball with no wand around it. Every kept centre carries the edge fit's covariance, and
// the notched one is marked partly hidden.
// Without edge centres the notched ball is left out, as before.
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "detect/blob_detector.h"
#include "formats/pgm.h"
#include "formats/recording.h"
#include "formats/rig_yaml.h"
#include "rigcal/rig_calibrator.h"
#include "tests/detect/synth.h"
#include "tests/rigcal/rigcal_fixture.h"
#include "tests/support/test_support.h"

namespace mocap::rigcal {
namespace {

constexpr int kWidth = 160, kHeight = 120;
constexpr double kRadiusPx = 4.0;
// The wand (0, 110, 300 mm) along image x, the rod leaving ball 0 towards ball 1.
const std::vector<Vec2> kWandPx = {
    {30.3, 60.2}, {30.3 + 90.0 * 110.0 / 300.0, 60.2}, {120.3, 60.2}};
const Vec2 kStrayPx(80.0, 20.0);

// A long lens: no perspective or distortion offset worth speaking of.
CameraModel camera(const std::string& name) {
  CameraModel c;
  c.name = name;
  c.width = kWidth;
  c.height = kHeight;
  c.fx = c.fy = 1.0e5;
  c.cx = 79.5;
  c.cy = 59.5;
  return c;
}

// The balls (ball 0 with a rod of 0.8 r hiding it from 0.3 r outwards towards ball 1),
// the stray (an ellipse 4:3) when asked, blur 0.5 px, noise 1.5 DN.
detect::test::SynthImage draw(bool wand, bool stray, std::uint32_t seed) {
  detect::test::SynthParams p;
  p.width = kWidth;
  p.height = kHeight;
  p.background_dn = 12.0;
  p.noise_sigma_dn = 1.5;
  p.blur_sigma_px = 0.5;
  p.seed = seed;
  std::vector<double> f(static_cast<std::size_t>(kWidth) * kHeight, 0.0);
  const double rod_w = 0.8 * kRadiusPx;
  const detect::test::Spot rod{
      kWandPx[0].x() + 0.3 * kRadiusPx + 10.0, kWandPx[0].y(), 10.0, 1.0, 0.5 * rod_w / 10.0, 0.0};
  std::vector<detect::test::Spot> spots;
  for (std::size_t k = 0; k < (wand ? 3u : 1u); ++k)
    spots.push_back({kWandPx[k].x(), kWandPx[k].y(), kRadiusPx, 180.0});
  if (stray) spots.push_back({kStrayPx.x(), kStrayPx.y(), 5.0, 180.0, 0.75, 0.4});
  for (std::size_t k = 0; k < spots.size(); ++k) {
    for (int y = 0; y < kHeight; ++y) {
      for (int x = 0; x < kWidth; ++x) {
        const double hidden = k == 0 ? detect::test::coverage(rod, x, y) : 0.0;
        f[static_cast<std::size_t>(y) * kWidth + x] +=
            spots[k].amplitude_dn * detect::test::coverage(spots[k], x, y) * (1.0 - hidden);
      }
    }
  }
  detect::test::blur(f, p);
  for (double& v : f) v += p.background_dn;
  return detect::test::quantise(f, p);
}

// Frame 0: the wand and the stray; frame 1: the notched ball alone. Both cameras alike.
void write_recording(const std::string& dir) {
  Rig rig;
  rig.cameras = {camera("cam0"), camera("cam1")};
  rig.cameras[1].t_cam_world = Vec3(-300.0, 0.0, 0.0);
  ASSERT_TRUE(save_rig(dir + "/rig.yaml", rig));
  ASSERT_TRUE(save_frames_csv(dir + "/frames.csv", {FrameEntry{0, 0}, FrameEntry{1, 10000000}}));
  for (const CameraModel& c : rig.cameras) {
    std::filesystem::create_directories(dir + "/" + c.name);
    ASSERT_TRUE(write_pgm(frame_file_path(dir, c.name, 0), draw(true, true, 3).view));
    ASSERT_TRUE(write_pgm(frame_file_path(dir, c.name, 1), draw(false, false, 4).view));
  }
}

const Vec2* nearest(const std::vector<Vec2>& pts, const Vec2& p, double within_px) {
  for (const Vec2& q : pts)
    if ((q - p).norm() < within_px) return &q;
  return nullptr;
}

TEST(DetectRecording, PartlyHiddenWandBallKeptFromItsEdge) {
  // Preconditions: the notched ball is less round than the filter's bar, its centroid is
  // pushed away from the rod, and the stray is far less round.
  const auto img = draw(true, true, 3);
  auto det = detect::BlobDetector::create(detect::DetectorConfig{}, kWidth, kHeight);
  ASSERT_TRUE(det);
  detect::BlobList list = det->make_blob_list();
  det->detect(img.view, list);
  ASSERT_EQ(list.size(), 4u);
  for (const detect::Blob& b : list) {
    const Vec2 c(b.x_px, b.y_px);
    if ((c - kWandPx[0]).norm() < 2.0) {
      EXPECT_LT(b.roundness, 0.95f * 0.97f);
      EXPECT_GT((c - kWandPx[0]).norm(), 0.25);
    }
    if ((c - kStrayPx).norm() < 2.0) {  // an ellipse 4:3
      EXPECT_LT(b.roundness, 0.8f);
    }
  }

  test::TempDir dir("detrec");
  write_recording(dir.path());
  const WandSpec wand = test::test_wand();
  auto out = detect_recording(dir.path(), RigCalOptions{}, nullptr, &wand);
  ASSERT_TRUE(out) << out.error().message;
  ASSERT_EQ(out->blobs.size(), 2u);
  ASSERT_EQ(out->info.size(), 2u);
  for (std::size_t c = 0; c < 2; ++c) {
    const auto& centres = out->blobs[0][c];
    const auto& info = out->info[0][c];
    ASSERT_EQ(centres.size(), 3u) << "the three wand balls, not the stray";
    ASSERT_EQ(info.size(), 3u);
    EXPECT_EQ(nearest(centres, kStrayPx, 3.0), nullptr);
    for (std::size_t k = 0; k < 3; ++k) {
      const Vec2* q = nearest(centres, kWandPx[k], 2.0);
      ASSERT_NE(q, nullptr) << "ball " << k;
      EXPECT_LT((*q - kWandPx[k]).norm(), 0.06) << "ball " << k;
      const CentreInfo& m = info[static_cast<std::size_t>(q - centres.data())];
      EXPECT_GT(m.cov_px2.trace(), 0.0) << "ball " << k;
      EXPECT_EQ(m.partly_hidden, k == 0) << "ball " << k;
    }
    EXPECT_TRUE(out->blobs[1][c].empty()) << "the notched ball alone is not a wand ball";
  }

  RigCalOptions centroids;
  centroids.edge_centres = false;
  auto plain = detect_recording(dir.path(), centroids, nullptr, &wand);
  ASSERT_TRUE(plain) << plain.error().message;
  ASSERT_EQ(plain->blobs[0][0].size(), 2u);
  EXPECT_EQ(nearest(plain->blobs[0][0], kWandPx[0], 2.0), nullptr);
  for (const CentreInfo& m : plain->info[0][0]) {
    EXPECT_EQ(m.cov_px2.trace(), 0.0);
    EXPECT_FALSE(m.partly_hidden);
  }
}

}  // namespace
}  // namespace mocap::rigcal
