// Tests of 2..8 cameras (`mocap simulate --cameras N`, `--rig` with 2..32 cameras): the
// built-in pair is exactly the pair it always was; every camera of the built-in 3..8
// camera arcs passes the scene-in-view check and the 4 cameras look from clearly
// different directions, so that limbs hide markers from some cameras and not others;
// a 3-camera user rig renders into 3 folders with per-camera ground-truth columns; a
// 4-camera wand recording has 4 cameras in gt/rig_true.yaml; the humanoid's ring takes
// up to 32 cameras (12: all in view, all aimed at the robot, its first 8 lenses those of
// the 8-camera ring); 1 and 9 cameras of the arc, 33 of a rig, are one-line errors.
// Lean: at most a few frames are rendered.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <string>

#include "core/rotation.h"
#include "core/units.h"
#include "formats/rig_yaml.h"
#include "sim/frame_writer.h"
#include "sim/render.h"
#include "sim/scene_cameras.h"
#include "sim/scene_rig.h"
#include "sim/simulate.h"
#include "sim/wand_sim.h"
#include "tests/support/test_support.h"

namespace mocap::sim {
namespace {

namespace fs = std::filesystem;

// The built-in pair as scene.cpp built it before the camera count became an option.
CameraModel previous_pair_camera(const char* name, double x_mm, const CameraMount& m, double fx,
                                 double fy, double cx, double cy, std::array<double, 5> dist,
                                 double roll_deg) {
  CameraModel cam;
  cam.name = name;
  cam.width = 1032;
  cam.height = 776;
  cam.fx = fx;
  cam.fy = fy;
  cam.cx = cx;
  cam.cy = cy;
  cam.distortion = dist;
  const Vec3 center(m.x_mm + x_mm, m.y_mm, m.z_mm);
  const Vec3 aim(m.x_mm, 250.0, m.aim_z_mm);
  const Vec3 z = (aim - center).normalized();
  const Vec3 x = z.cross(Vec3::UnitZ()).normalized();
  const Vec3 y = z.cross(x);
  Mat3 R;
  R.row(0) = x.transpose();
  R.row(1) = y.transpose();
  R.row(2) = z.transpose();
  R = rot_z(roll_deg * kRadPerDeg) * R;
  cam.R_cam_world = R;
  cam.t_cam_world = -R * center;
  return cam;
}

TEST(SimCameras, TwoCamerasAreThePreviousBuiltInPair) {
  for (SceneKind kind : {SceneKind::kLimbs, SceneKind::kStalks}) {
    SimOptions opt;
    opt.scene = kind;
    for (int cameras : {0, 2}) {
      opt.cameras = cameras;
      auto scene = make_scene(opt);
      ASSERT_TRUE(scene.ok()) << scene.error().message;
      const CameraMount m = camera_mount(kind);
      const Rig expected{{previous_pair_camera("cam0", -238.5, m, 1291.2, 1290.6, 517.3, 385.9,
                                               {-0.121, 0.083, 0.0004, -0.0003, 0.0}, 0.3),
                          previous_pair_camera("cam1", 238.5, m, 1288.7, 1288.1, 513.8, 389.4,
                                               {-0.118, 0.079, -0.0002, 0.0005, 0.0}, -0.4)}};
      ASSERT_EQ(scene->rig.cameras.size(), 2u);
      for (std::size_t c = 0; c < 2; ++c) {
        const CameraModel& a = scene->rig.cameras[c];
        const CameraModel& b = expected.cameras[c];
        EXPECT_EQ(a.name, b.name);
        EXPECT_EQ(a.fx, b.fx);
        EXPECT_EQ(a.cy, b.cy);
        EXPECT_EQ(a.distortion, b.distortion);
        EXPECT_TRUE(a.R_cam_world == b.R_cam_world) << c;  // bit for bit
        EXPECT_TRUE(a.t_cam_world == b.t_cam_world) << c;
      }
    }
  }
  EXPECT_EQ(markers_csv_camera_columns(2, true),
            "u0,v0,vis0,u1,v1,vis1,frac0,merged0,dropped0,frac1,merged1,dropped1");
  EXPECT_EQ(markers_csv_camera_columns(3, false), "u0,v0,vis0,u1,v1,vis1,u2,v2,vis2");
}

TEST(SimCameras, EveryBuiltInArcPassesTheSceneCheck) {
  for (int n = 3; n <= kMaxArcCameras; ++n) {
    SimOptions opt;
    opt.cameras = n;
    auto scene = make_scene(opt);  // runs the check itself
    ASSERT_TRUE(scene.ok()) << n << ": " << scene.error().message;
    ASSERT_EQ(scene->rig.cameras.size(), static_cast<std::size_t>(n));
    EXPECT_TRUE(check_rig_for_scene(scene->rig, *scene, "arc").ok()) << n;
    for (int c = 0; c < n; ++c) {  // and each camera on its own (with a copy as partner)
      Rig one{{scene->rig.cameras[static_cast<std::size_t>(c)],
               scene->rig.cameras[static_cast<std::size_t>(c)]}};
      one.cameras[1].name = "copy";
      auto r = check_rig_for_scene(one, *scene, "arc");
      EXPECT_TRUE(r.ok()) << n << " cameras, camera " << c << ": " << r.error().message;
    }
  }
}

TEST(SimCameras, TheHumanoidRingTakesMoreThanEightCameras) {
  SimOptions opt;
  opt.scene = SceneKind::kHumanoid;
  opt.cameras = 12;
  auto twelve = make_scene(opt);  // runs the scene check itself
  ASSERT_TRUE(twelve.ok()) << twelve.error().message;
  ASSERT_EQ(twelve->rig.cameras.size(), 12u);
  EXPECT_TRUE(check_rig_for_scene(twelve->rig, *twelve, "ring").ok());
  opt.cameras = 8;
  auto eight = make_scene(opt);
  ASSERT_TRUE(eight.ok()) << eight.error().message;
  for (std::size_t c = 0; c < 12; ++c) {
    const CameraModel& cam = twelve->rig.cameras[c];
    EXPECT_EQ(cam.name, "cam" + std::to_string(c));
    const Vec3 z = cam.R_cam_world.row(2).transpose();
    const Vec3 to_center = twelve->robot_center_world - cam.center_world();
    EXPECT_GT(z.dot(to_center.normalized()), 0.999) << c;
    EXPECT_EQ(cam.fx, eight->rig.cameras[c % 8].fx) << c;  // lens k % 8
    for (std::size_t d = 0; d < c; ++d)                    // 30 deg apart on the ring
      EXPECT_GT((cam.center_world() - twelve->rig.cameras[d].center_world()).norm(), 1000.0);
  }
  opt.cameras = 33;
  auto too_many = make_scene(opt);
  ASSERT_FALSE(too_many.ok());
  EXPECT_EQ(too_many.error().message, "simulate: cameras: must be 2..32 for this scene, got 33");
}

TEST(SimCameras, FourCamerasSeeTheRobotFromDifferentSides) {
  SimOptions opt;
  opt.cameras = 4;
  auto scene = make_scene(opt);
  ASSERT_TRUE(scene.ok()) << scene.error().message;
  const Rig& rig = scene->rig;
  // Optical axes at least 60 deg apart horizontally, every camera aimed at the robot.
  for (std::size_t a = 0; a < 4; ++a) {
    const Vec3 za = rig.cameras[a].R_cam_world.row(2).transpose();
    const Vec3 to_center = scene->robot_center_world - rig.cameras[a].center_world();
    EXPECT_GT(za.dot(to_center.normalized()), 0.9999) << a;
    for (std::size_t b = 0; b < a; ++b) {
      const Vec3 zb = rig.cameras[b].R_cam_world.row(2).transpose();
      const double cos_h = za.head<2>().normalized().dot(zb.head<2>().normalized());
      EXPECT_LT(cos_h, std::cos(60.0 * kRadPerDeg)) << a << " " << b;
    }
  }
  // Occlusion is per camera: at the reference configuration every camera misses some
  // marker another camera sees isolated, and every marker is isolated in some camera
  // or hidden in all of them for a reason (none is out of the images).
  auto renderer = MultiRender::create(*scene, 2);
  ASSERT_TRUE(renderer.ok()) << renderer.error().message;
  std::vector<Image> images = make_camera_images(*scene);
  SceneState state = make_state(*scene);
  ASSERT_TRUE(renderer->render(state, images).ok());
  for (int c = 0; c < 4; ++c) {
    int hidden_here_seen_elsewhere = 0;
    for (int m = 0; m < scene->marker_count(); ++m) {
      const auto um = static_cast<std::size_t>(m);
      const MarkerView& mv = renderer->views(c).markers[um];
      EXPECT_TRUE(mv.in_front && mv.inside_image) << c << " " << m;
      bool elsewhere = false;
      for (int d = 0; d < 4; ++d) elsewhere |= d != c && renderer->views(d).markers[um].isolated();
      hidden_here_seen_elsewhere += (!mv.isolated() && elsewhere) ? 1 : 0;
    }
    EXPECT_GE(hidden_here_seen_elsewhere, 1) << "camera " << c;
  }
}

// Geometry only (no rendering): share of frames in which every marker projects inside
// every camera's image, per motion, for the built-in arcs. Printed; the 4-camera
// arc keeps the whole robot in view in most frames of every motion.
TEST(SimCameras, ArcKeepsTheRobotInViewOverTheMotions) {
  for (int n : {3, 4, 6, 8}) {
    SimOptions opt;
    opt.cameras = n;
    auto scene = make_scene(opt);
    ASSERT_TRUE(scene.ok()) << scene.error().message;
    for (MotionKind kind :
         {MotionKind::kSmooth, MotionKind::kPoses, MotionKind::kMove400, MotionKind::kViewpoints}) {
      MotionSpec spec;
      spec.kind = kind;
      spec.frames = 220;
      auto plan = plan_motion(*scene, spec);
      ASSERT_TRUE(plan.ok());
      SceneState state = make_state(*scene);
      int all_in = 0;
      double worst_margin = 1e9;  // px from the image border (negative: outside)
      for (const JointConfig& config : plan->configs) {
        apply_config(*scene, config, state);
        bool in = true;
        for (const CameraModel& cam : scene->rig.cameras) {
          for (int m = 0; m < scene->marker_count(); ++m) {
            const auto um = static_cast<std::size_t>(m);
            const Vec3 X = state.T_world_body[static_cast<std::size_t>(scene->marker_body[um])] *
                           scene->marker_in_body(m);
            Vec2 px;
            if (!project(cam, X, px)) {
              in = false;
              worst_margin = std::min(worst_margin, -1e6);
              continue;
            }
            const double margin =
                std::min({px.x(), px.y(), cam.width - 1.0 - px.x(), cam.height - 1.0 - px.y()});
            worst_margin = std::min(worst_margin, margin);
            in = in && margin >= 0.0;
          }
        }
        all_in += in ? 1 : 0;
      }
      std::printf("%d cameras, %s: all markers in all images in %d of %zu frames, worst %.0f px\n",
                  n, motion_name(kind), all_in, plan->configs.size(), worst_margin);
      if (n == 4) {
        EXPECT_GE(all_in, static_cast<int>(plan->configs.size()) * 9 / 10);
      }
    }
  }
}

TEST(SimCameras, ThreeCameraUserRigRenders) {
  test::TempDir dir("sim_rig3");
  auto pair = make_scene(SimOptions{});
  auto wide = load_rig(test::source_dir() + "/docs/rigs/wide.yaml");
  ASSERT_TRUE(pair.ok() && wide.ok());
  Rig rig = pair->rig;
  rig.cameras.push_back(wide->cameras[0]);
  rig.cameras[2].name = "side";
  ASSERT_TRUE(save_rig(dir.file("rig3.yaml"), rig).ok());
  SimOptions opt;
  opt.rig_path = dir.file("rig3.yaml");
  opt.frames = 2;
  opt.threads = 2;
  const std::string out = dir.file("rec");
  auto sum = write_simulated_recording(opt, out);
  ASSERT_TRUE(sum.ok()) << sum.error().message;
  EXPECT_EQ(sum->cameras, 3);
  EXPECT_EQ(sum->marker_views, 2 * 16 * 3);
  EXPECT_GT(sum->isolated_views, 0);
  for (const char* f : {"cam0/000001.pgm", "cam1/000001.pgm", "side/000001.pgm"})
    EXPECT_TRUE(fs::exists(out + "/" + f)) << f;
  auto written = load_rig(out + "/rig.yaml");
  ASSERT_TRUE(written.ok());
  EXPECT_EQ(written->cameras.size(), 3u);
  const std::string gt = test::read_file(out + "/gt/markers.csv");
  EXPECT_EQ(gt.substr(0, gt.find('\n')),
            "frame,body,marker,x,y,z,u0,v0,vis0,u1,v1,vis1,u2,v2,vis2,"
            "frac0,merged0,dropped0,frac1,merged1,dropped1,frac2,merged2,dropped2");
  EXPECT_EQ(test::line_count(gt), 1 + 2 * 16);
  // --cameras must agree with the rig.
  opt.cameras = 2;
  auto bad = write_simulated_recording(opt, dir.file("bad"));
  ASSERT_FALSE(bad.ok());
  EXPECT_EQ(bad.error().message.rfind("simulate: cameras: 2 requested but the rig ", 0), 0u)
      << bad.error().message;
}

TEST(SimCameras, FourCameraWandRecording) {
  test::TempDir dir("sim_wand4");
  SimOptions opt;
  opt.cameras = 4;
  opt.frames = 2;
  auto sum = write_calibration_recording(opt, CalibObjectKind::kWand, dir.path());
  ASSERT_TRUE(sum.ok()) << sum.error().message;
  EXPECT_EQ(sum->cameras, 4);
  auto truth = load_rig(dir.file("gt/rig_true.yaml"));
  ASSERT_TRUE(truth.ok()) << truth.error().message;
  ASSERT_EQ(truth->cameras.size(), 4u);
  EXPECT_EQ(truth->cameras[3].name, "cam3");
  EXPECT_TRUE(fs::exists(dir.file("cam3/000001.pgm")));
  const std::string gt = test::read_file(dir.file("gt/markers.csv"));
  EXPECT_EQ(gt.substr(0, gt.find('\n')),
            "frame,marker,x,y,z,u0,v0,vis0,u1,v1,vis1,u2,v2,vis2,u3,v3,vis3");
}

TEST(SimCameras, OneAndNineCamerasAreOneLineErrors) {
  for (int n : {1, 9, 0 - 1}) {
    SimOptions opt;
    opt.cameras = n;
    auto s = make_scene(opt);
    ASSERT_FALSE(s.ok()) << n;
    EXPECT_EQ(s.error().message,
              "simulate: cameras: must be 2..8 for this scene, got " + std::to_string(n));
  }
  test::TempDir dir("sim_rig19");
  auto pair = make_scene(SimOptions{});
  ASSERT_TRUE(pair.ok());
  for (int n : {1, 33}) {
    Rig rig;
    for (int c = 0; c < n; ++c) {
      rig.cameras.push_back(pair->rig.cameras[static_cast<std::size_t>(c % 2)]);
      rig.cameras.back().name = "cam" + std::to_string(c);
    }
    const std::string path = dir.file("rig" + std::to_string(n) + ".yaml");
    ASSERT_TRUE(save_rig(path, rig).ok());
    SimOptions opt;
    opt.rig_path = path;
    auto s = make_scene(opt);
    ASSERT_FALSE(s.ok()) << n;
    // 33 cameras: the rig reader already refuses more than kMaxCameras.
    const std::string expected =
        n == 33 ? path + ": cameras: 33 cameras, at most 32 are supported"
                : path + ": cameras: the simulator renders 2 to 32 cameras, the rig has 1";
    EXPECT_EQ(s.error().message.rfind(expected, 0), 0u) << s.error().message;
    EXPECT_EQ(s.error().message.find('\n'), std::string::npos);
  }
}

}  // namespace
}  // namespace mocap::sim
