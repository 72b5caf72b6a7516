// Design: the rig calibration of more than two cameras on synthetic wand observations
// (rigcal_fixture.h: four cameras on a ring 2-3 m around a robot at different heights,
// the wand at random poses in front of the robot and hidden from each camera in 15% of
// the frames; projected markers with Gaussian pixel noise, no rendering). Checks every
// camera's pose relative to camera 0 against the truth (the acceptance: 0.1 mm
// and 0.01 degrees), the chain through the best-connected camera, the one-line errors
// (a camera that cannot be connected, 33 cameras) and the N-camera ground frame.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <random>

#include "tests/rigcal/rigcal_fixture.h"

namespace mocap::rigcal {
namespace {

using test::cam0_world;
using test::ring_cameras;
using test::ring_wand_blobs;

// Assumed for the acceptance (0.1 mm, 0.01 degrees): Gaussian pixel noise of 0.05 px
// per axis on every marker centre (a well-focused ~10 px marker, subpixel centroid),
// 1000 wand frames (~30 s of waving at 30 fps), the true intrinsics (kFixed). The
// position error is the wand's scale error (~2e-5 of the 3.3-4.8 m baselines, in
// proportion to the noise, zero without noise): with 0.08 px and 400 frames the
// centres are off by 0.14-0.16 mm, with 0.05 px and 1000 frames by at most 0.098 mm
// over seeds 21-26 (0.079 mm for this seed); docs/rig_calibration.md.
constexpr double kNoisePx = 0.05;
constexpr int kFrames = 1000;

TEST(RigCalibratorN, FourCameraRingWithinAcceptance) {
  const auto world = ring_cameras(4);
  const auto truth = cam0_world(world);
  const auto blobs = ring_wand_blobs(world, test::test_wand(), kFrames, kNoisePx, 0.15, 21);
  RigCalOptions opt;
  opt.intrinsics = IntrinsicsMode::kFixed;
  auto r = calibrate_from_blobs(blobs, test::test_wand(), world, opt, "rec");
  ASSERT_TRUE(r) << r.error().message;
  ASSERT_EQ(r->cameras.size(), 4u);
  ASSERT_EQ(r->quality.size(), 4u);
  EXPECT_TRUE(r->cameras[0].R_cam_world.isIdentity(1e-12));
  EXPECT_GT(r->frames_used, 800);
  for (std::size_t c = 1; c < 4; ++c) {
    const double pos_mm = (r->cameras[c].center_world() - truth[c].center_world()).norm();
    const double rot_deg =
        test::rotation_error_deg(r->cameras[c].R_cam_world, truth[c].R_cam_world);
    std::printf(
        "[ ring4 ] %s: baseline %.1f mm, centre error %.4f mm, rotation error %.5f deg, "
        "RMS %.3f px, %d frames used, from %s\n",
        r->quality[c].name.c_str(), r->quality[c].baseline_mm, pos_mm, rot_deg,
        r->quality[c].reprojection_rms_px, r->quality[c].frames_used,
        r->quality[c].initialised_from.c_str());
    EXPECT_LT(pos_mm, 0.1) << r->quality[c].name;
    EXPECT_LT(rot_deg, 0.01) << r->quality[c].name;
    EXPECT_EQ(r->quality[c].initialised_from, "cam0");
    EXPECT_NEAR(r->quality[c].baseline_mm, truth[c].center_world().norm(), 0.1);
    EXPECT_LT(r->quality[c].reprojection_rms_px, 1.5 * kNoisePx);
    EXPECT_GT(r->quality[c].reprojection_rms_px, 0.5 * kNoisePx);
  }
  EXPECT_LT(r->wand_length_rms_error_mm, 0.25);  // per frame, 2.5-4.5 m away
  EXPECT_NEAR(r->baseline_mm, r->quality[1].baseline_mm, 1e-12);
}

// The wand's centres with noise of two kinds, as the edge fits give them: most precise
// (0.02 px), some partly hidden balls far less so along one axis (0.15 x 0.04 px), each
// with its covariance. Weighed by it, the rig is closer to the truth than with every
// centre weighing the same (the squared error under half); with one covariance for all,
// the weights change nothing. The poor centres are marked partly hidden, which keeps
// their frames out of the wand-length figure; a centre far off with a covariance that
// says so does not drop its frame.
TEST(RigCalibratorN, CovarianceWeighsTheCentres) {
  const auto world = ring_cameras(4);
  const auto truth = cam0_world(world);
  FrameBlobs blobs = ring_wand_blobs(world, test::test_wand(), 300, 0.0, 0.15, 24);
  FrameCentreInfo cov(blobs.size()), same(blobs.size());
  std::mt19937_64 rng(24);
  std::normal_distribution<double> g(0.0, 1.0);
  std::uniform_real_distribution<double> u01(0.0, 1.0);
  for (std::size_t f = 0; f < blobs.size(); ++f) {
    cov[f].resize(blobs[f].size());
    same[f].resize(blobs[f].size());
    for (std::size_t c = 0; c < blobs[f].size(); ++c) {
      for (Vec2& p : blobs[f][c]) {
        const bool poor = u01(rng) < 0.3;
        const Vec2 sd = poor ? Vec2(0.15, 0.04) : Vec2(0.02, 0.02);
        p += Vec2(sd.x() * g(rng), sd.y() * g(rng));
        cov[f][c].push_back(CentreInfo{sd.cwiseAbs2().asDiagonal(), poor});
        same[f][c].push_back(CentreInfo{0.0025 * Eigen::Matrix2d::Identity(), poor});
      }
    }
  }
  for (std::size_t f = 0, n = 0; f < blobs.size() && n < 20; ++f) {
    if (blobs[f][0].size() != 3) continue;
    blobs[f][0][1] += Vec2(1.0, 0.0);
    cov[f][0][1] = CentreInfo{0.25 * Eigen::Matrix2d::Identity(), true};
    same[f][0][1].partly_hidden = true;
    ++n;
  }
  RigCalOptions opt;
  opt.intrinsics = IntrinsicsMode::kFixed;
  auto weighted = calibrate_from_blobs(blobs, test::test_wand(), world, opt, "rec", &cov);
  auto uniform = calibrate_from_blobs(blobs, test::test_wand(), world, opt, "rec", &same);
  opt.weight_centres = false;
  auto plain = calibrate_from_blobs(blobs, test::test_wand(), world, opt, "rec", &cov);
  ASSERT_TRUE(weighted && uniform && plain);
  double ss_weighted = 0.0, ss_plain = 0.0;
  for (std::size_t c = 1; c < 4; ++c) {
    const Vec3 C = truth[c].center_world();
    ss_weighted += (weighted->cameras[c].center_world() - C).squaredNorm();
    ss_plain += (plain->cameras[c].center_world() - C).squaredNorm();
    EXPECT_LT((uniform->cameras[c].center_world() - plain->cameras[c].center_world()).norm(), 1e-6);
  }
  std::printf("[ weights ] camera centres' RMS error: weighted %.4f mm, unweighted %.4f mm\n",
              std::sqrt(ss_weighted / 3.0), std::sqrt(ss_plain / 3.0));
  EXPECT_LT(ss_weighted, 0.5 * ss_plain);
  // A poor centre is held to its own noise by the outlier test, not to the median's:
  // 20 frames with one centre 1 px off and a sigma of 0.5 px (2 sigma) are kept, while
  // unweighted 1 px is far beyond 5 x the RMS and drops them.
  std::printf("[ weights ] frames used: weighted %d, unweighted %d\n", weighted->frames_used,
              plain->frames_used);
  EXPECT_GE(weighted->frames_used, plain->frames_used + 15);
  // The wand-length figure counts only frames whose end balls are whole everywhere
  // (30 % of the centres are marked partly hidden: ~10 % of the frames qualify).
  EXPECT_GT(weighted->wand_length_samples, 10);
  EXPECT_LT(weighted->wand_length_samples,
            weighted->frames_used / 4);  // 0.27 here; 0.07-0.3 over other seeds
}

TEST(RigCalibratorN, ChainsThroughTheBestConnectedCamera) {
  const auto world = ring_cameras(4);
  const auto truth = cam0_world(world);
  auto blobs = ring_wand_blobs(world, test::test_wand(), 240, kNoisePx, 0.1, 22);
  // cam3 and cam0 share only a few frames: cam0 misses the wand whenever cam3 sees it,
  // except in 10 frames.
  int kept = 0;
  for (auto& f : blobs) {
    if (f[0].size() == 3 && f[3].size() == 3 && ++kept > 10) f[0].clear();
  }
  RigCalOptions opt;
  opt.intrinsics = IntrinsicsMode::kFixed;
  auto r = calibrate_from_blobs(blobs, test::test_wand(), world, opt, "rec");
  ASSERT_TRUE(r) << r.error().message;
  EXPECT_NE(r->quality[3].initialised_from, "cam0");
  EXPECT_EQ(r->quality[1].initialised_from, "cam0");
  // The joint bundle then finds the right rig (240 frames, cam0 in fewer of them: the
  // statistical error is larger than in the acceptance case).
  for (std::size_t c = 1; c < 4; ++c) {
    EXPECT_LT((r->cameras[c].center_world() - truth[c].center_world()).norm(), 0.5);
    EXPECT_LT(test::rotation_error_deg(r->cameras[c].R_cam_world, truth[c].R_cam_world), 0.01);
  }
}

TEST(RigCalibratorN, UnconnectedCameraIsAnError) {
  const auto world = ring_cameras(4);
  auto blobs = ring_wand_blobs(world, test::test_wand(), 120, kNoisePx, 0.1, 23);
  // cam2 sees the wand only in frames where no other camera does.
  for (std::size_t f = 0; f < blobs.size(); ++f) {
    if (f % 4 == 0) {
      for (std::size_t c : {0u, 1u, 3u}) blobs[f][c].clear();
    } else {
      blobs[f][2].clear();
    }
  }
  auto r = calibrate_from_blobs(blobs, test::test_wand(), world, RigCalOptions{}, "rec");
  ASSERT_FALSE(r);
  EXPECT_NE(r.error().message.find("rec: cam2: cannot be connected to cam0"), std::string::npos)
      << r.error().message;
  EXPECT_EQ(r.error().message.find('\n'), std::string::npos);
}

TEST(RigCalibratorN, CameraCountErrors) {
  for (int n : {1, 33}) {
    const auto world = ring_cameras(n);
    const FrameBlobs blobs(40, std::vector<std::vector<Vec2>>(static_cast<std::size_t>(n)));
    auto r = calibrate_from_blobs(blobs, test::test_wand(), world, RigCalOptions{}, "rec");
    ASSERT_FALSE(r);
    EXPECT_EQ(r.error().message, "rec/rig.yaml: cameras: " + std::to_string(n) +
                                     " cameras listed, a rig calibration takes 2 to 32");
  }
  // Blobs of a different camera count than the rig.
  const auto world = ring_cameras(3);
  const FrameBlobs blobs(40, std::vector<std::vector<Vec2>>(2));
  auto r = calibrate_from_blobs(blobs, test::test_wand(), world, RigCalOptions{}, "rec");
  ASSERT_FALSE(r);
  EXPECT_NE(r.error().message.find("rec: frame 0: blobs of 2 cameras, the rig has 3"),
            std::string::npos)
      << r.error().message;
}

TEST(GroundFrame, FromLFrameObservationsFourCameras) {
  const auto world = ring_cameras(4);  // world = the robot's frame
  const auto cams = cam0_world(world);
  LFrameSpec lf;
  lf.markers_mm = {Vec3(0, 0, 6), Vec3(400, 0, 6), Vec3(0, 250, 6), Vec3(200, 0, 6)};
  const Iso3 T_world_lframe =
      make_iso(Eigen::AngleAxisd(0.4, Vec3::UnitZ()).toRotationMatrix(), Vec3(-150.0, 80.0, 0.0));
  std::mt19937_64 rng(5);
  std::normal_distribution<double> g(0.0, kNoisePx);
  FrameBlobs blobs(10, std::vector<std::vector<Vec2>>(4));
  for (std::size_t f = 0; f < blobs.size(); ++f) {
    for (std::size_t c = 0; c < 4; ++c) {
      for (std::size_t m = 0; m < lf.markers_mm.size(); ++m) {
        if ((c + m) % 4 == 3) continue;  // each marker hidden from one camera
        Vec2 px;
        ASSERT_TRUE(project(world[c], T_world_lframe * lf.markers_mm[m], px));
        blobs[f][c].push_back(px + Vec2(g(rng), g(rng)));
      }
      blobs[f][c].push_back(Vec2(40.0 + 13.0 * static_cast<double>(c), 70.0));  // a static stray
    }
  }
  RigCalResult res;
  res.cameras = cams;
  ASSERT_TRUE(set_ground_frame(res, blobs, lf, RigCalOptions{}, "lf"));
  const Rig expected = sim::rig_in_lframe(Rig{world}, T_world_lframe);
  // The cameras are 2.5-4.5 m from the 400 mm L-frame: the fit's rotation error
  // (~0.01 degrees) moves their centres by up to ~0.8 mm.
  for (std::size_t c = 0; c < 4; ++c) {
    EXPECT_LT((res.cameras[c].center_world() - expected.cameras[c].center_world()).norm(), 1.0);
    EXPECT_LT(test::rotation_error_deg(res.cameras[c].R_cam_world, expected.cameras[c].R_cam_world),
              0.02);
  }
  EXPECT_LT(res.ground.rms_mm, 0.1);
}

}  // namespace
}  // namespace mocap::rigcal
