// Design: the calibration pipeline on synthetic wand observations (true rig of the
// simulator, projected wand markers with noise and strays): bundle adjustment from
// perturbed extrinsics and intrinsics, the whole calibrate_from_blobs path, its
// one-line errors (too few frames, wand never seen by a camera, wrong spacing), and
// the L-frame ground frame.
#include <gtest/gtest.h>

#include "core/rotation.h"
#include "tests/rigcal/rigcal_fixture.h"

namespace mocap::rigcal {
namespace {

using test::cam0_world;
using test::synthetic_wand_blobs;
using test::true_cameras;

// Frames with every marker in both images, in wand order (no strays in these blobs).
void make_frames(const std::vector<CameraModel>& cams, int n, std::vector<WandFrame>& frames,
                 std::vector<WandPose>& poses) {
  (void)cams;  // the blobs come from the true cameras in the simulator's world
  const auto world = true_cameras();
  const auto blobs = synthetic_wand_blobs(world, mocap::test::test_wand(), n, 0.05, 0, 7);
  const Iso3 T_cam0_world = world[0].T_cam_world();
  for (int f = 0; f < n; ++f) {
    const auto& b = blobs[static_cast<std::size_t>(f)];
    if (b[0].size() != 3 || b[1].size() != 3) continue;
    WandFrame wf;
    wf.frame = f;
    wf.px = {b[0], b[1]};
    frames.push_back(wf);
    const Iso3 T = T_cam0_world * sim::wand_pose(f, n, 7);
    WandPose p;
    p.A = T * Vec3(-150.0, 0, 0) + Vec3(3.0, -2.0, 4.0);  // perturbed start
    p.d = (T.linear().col(0) + Vec3(0.02, -0.01, 0.015)).normalized();
    poses.push_back(p);
  }
}

TEST(Bundle, ConvergesFromPerturbedExtrinsics) {
  const auto truth = cam0_world(true_cameras());
  std::vector<WandFrame> frames;
  std::vector<WandPose> poses;
  make_frames(truth, 80, frames, poses);
  ASSERT_GE(frames.size(), 50u);
  auto cams = truth;
  cams[1].R_cam_world = truth[1].R_cam_world * rot_y(0.02) * rot_x(-0.01);
  cams[1].t_cam_world = truth[1].t_cam_world + Vec3(12.0, -6.0, 9.0);
  std::vector<bool> use(frames.size(), true);
  auto poses_ref = poses;
  auto st = bundle_adjust(mocap::test::test_wand(), frames, use, cams, poses, BundleOptions{});
  ASSERT_TRUE(st) << st.error().message;
  EXPECT_TRUE(st->converged);
  // The same optimum as when started at the truth...
  auto ref = truth;
  std::vector<bool> use_ref(frames.size(), true);
  ASSERT_TRUE(
      bundle_adjust(mocap::test::test_wand(), frames, use_ref, ref, poses_ref, BundleOptions{}));
  EXPECT_LT((cams[1].center_world() - ref[1].center_world()).norm(), 1e-4);
  EXPECT_LT(test::rotation_error_deg(cams[1].R_cam_world, ref[1].R_cam_world), 1e-6);
  // ... which is close to the truth (0.05 px noise, 80 frames).
  EXPECT_LT((cams[1].center_world() - truth[1].center_world()).norm(), 0.3);
  EXPECT_LT(test::rotation_error_deg(cams[1].R_cam_world, truth[1].R_cam_world), 0.01);
  EXPECT_LT(st->rms_px[0], 0.08);
  EXPECT_LT(st->rms_px[1], 0.08);
  EXPECT_GT(st->rms_px[0], 0.02);  // the noise is really there
}

TEST(Bundle, RefinesPerturbedIntrinsics) {
  const auto truth = cam0_world(true_cameras());
  std::vector<WandFrame> frames;
  std::vector<WandPose> poses;
  make_frames(truth, 120, frames, poses);
  auto cams = truth;
  cams[0].fx *= 1.004;
  cams[0].fy *= 1.004;
  cams[0].cx += 3.0;
  cams[1].cy -= 3.0;
  cams[1].distortion[0] += 0.01;
  std::vector<bool> use(frames.size(), true);
  BundleOptions o;
  o.refine_intrinsics = true;
  o.outlier_px = 10.0;
  auto st = bundle_adjust(mocap::test::test_wand(), frames, use, cams, poses, o);
  ASSERT_TRUE(st) << st.error().message;
  EXPECT_LT(std::fabs(cams[0].cx - truth[0].cx), 1.0);
  EXPECT_LT(std::fabs(cams[1].cy - truth[1].cy), 1.0);
  EXPECT_LT(std::fabs(cams[0].fx - truth[0].fx), 2.0);
  EXPECT_LT(std::fabs(cams[1].distortion[0] - truth[1].distortion[0]), 0.003);
  EXPECT_LT(st->rms_px[1], 0.08);
}

TEST(RigCalibrator, CalibratesFromBlobsWithStrays) {
  const auto world = true_cameras();
  const auto truth = cam0_world(world);
  const auto blobs = synthetic_wand_blobs(world, mocap::test::test_wand(), 120, 0.05, 2, 11);
  RigCalOptions opt;
  opt.intrinsics = IntrinsicsMode::kFixed;
  auto r = calibrate_from_blobs(blobs, mocap::test::test_wand(), world, opt, "rec");
  ASSERT_TRUE(r) << r.error().message;
  EXPECT_NEAR(r->baseline_mm, truth[1].center_world().norm(), 0.1);
  EXPECT_LT(test::rotation_error_deg(r->cameras[1].R_cam_world, truth[1].R_cam_world), 0.01);
  EXPECT_LT(r->wand_length_rms_error_mm, 0.3);
  EXPECT_GT(r->frames_used, 60);
  EXPECT_FALSE(r->intrinsics_refined);
  EXPECT_FALSE(r->warnings.empty());  // 120 frames: the "too few frames" warning
  EXPECT_TRUE(r->cameras[0].R_cam_world.isIdentity(1e-12));
}

TEST(RigCalibrator, Errors) {
  const auto world = true_cameras();
  const auto blobs = synthetic_wand_blobs(world, mocap::test::test_wand(), 40, 0.05, 0, 13);
  RigCalOptions opt;
  opt.min_frames = 60;
  auto r = calibrate_from_blobs(blobs, mocap::test::test_wand(), world, opt, "rec");
  ASSERT_FALSE(r);
  EXPECT_NE(r.error().message.find("rec: frames: too few frames"), std::string::npos)
      << r.error().message;
  auto blind = blobs;
  for (auto& f : blind) f[1].clear();
  r = calibrate_from_blobs(blind, mocap::test::test_wand(), world, RigCalOptions{}, "rec");
  ASSERT_FALSE(r);
  EXPECT_NE(r.error().message.find("rec: cam1: the wand was never found"), std::string::npos)
      << r.error().message;
  WandSpec wrong = mocap::test::test_wand();
  wrong.markers_mm = {0.0, 125.0, 300.0};  // close enough to label, wrong in 3D
  const auto blobs2 = synthetic_wand_blobs(world, mocap::test::test_wand(), 60, 0.05, 0, 13);
  r = calibrate_from_blobs(blobs2, wrong, world, RigCalOptions{}, "rec");
  ASSERT_FALSE(r);
  EXPECT_NE(r.error().message.find("wrong wand spacing"), std::string::npos) << r.error().message;
  wrong.markers_mm = {0.0, 60.0, 300.0};  // far off: never labelled
  r = calibrate_from_blobs(blobs2, wrong, world, RigCalOptions{}, "rec");
  ASSERT_FALSE(r);
  EXPECT_NE(r.error().message.find("never found"), std::string::npos) << r.error().message;
  EXPECT_EQ(r.error().message.find('\n'), std::string::npos);
}

TEST(GroundFrame, FromLFrameObservations) {
  const auto truth_world = true_cameras();
  const auto cams = cam0_world(truth_world);
  const LFrameSpec lf = sim::default_calibration_objects().lframe;
  const Iso3 T_world_lframe = sim::simulated_T_world_lframe();
  std::mt19937_64 rng(3);
  std::normal_distribution<double> g(0.0, 0.05);
  FrameBlobs blobs(10, std::vector<std::vector<Vec2>>(2));
  for (auto& fb : blobs) {
    for (std::size_t c = 0; c < 2; ++c) {
      for (const Vec3& p : lf.markers_mm) {
        Vec2 px;
        ASSERT_TRUE(project(truth_world[c], T_world_lframe * p, px));
        fb[c].push_back(px + Vec2(g(rng), g(rng)));
      }
      fb[c].push_back(Vec2(50.0 + 10.0 * static_cast<double>(c), 60.0));  // a static stray
    }
  }
  RigCalResult res;
  res.cameras = cams;
  ASSERT_TRUE(set_ground_frame(res, blobs, lf, RigCalOptions{}, "lf"));
  const Rig expected = sim::rig_in_lframe(Rig{{truth_world[0], truth_world[1]}}, T_world_lframe);
  for (std::size_t c = 0; c < 2; ++c) {
    EXPECT_LT((res.cameras[c].center_world() - expected.cameras[c].center_world()).norm(), 0.5);
    EXPECT_LT(test::rotation_error_deg(res.cameras[c].R_cam_world, expected.cameras[c].R_cam_world),
              0.02);
  }
  EXPECT_LT(res.ground.rms_mm, 0.1);
  // The wrong L-frame layout is an error.
  LFrameSpec wrong = lf;
  wrong.markers_mm[2] = Vec3(0, 300, 0);
  RigCalResult res2;
  res2.cameras = cams;
  auto r = set_ground_frame(res2, blobs, wrong, RigCalOptions{}, "lf");
  ASSERT_FALSE(r);
  EXPECT_NE(r.error().message.find("lf: lframe: "), std::string::npos) << r.error().message;
}

}  // namespace
}  // namespace mocap::rigcal
