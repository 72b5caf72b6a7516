// Rendering through user-given rigs (`mocap simulate --rig`): the documented example
// rigs (docs/rigs: strong barrel, pincushion, off-centre principal points, wide angle)
// load, pass the scene check, and render the scene with every marker inside both
// images; isolated markers appear where the camera model says (background-subtracted
// centroid near project() of the sphere centre, triangulation near the truth), also
// with 16-bit output. Bad rigs (9 cameras, scene out of view, a folding lens,
// a missing file) give one-line errors naming the rig file.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <string>

#include "formats/rig_yaml.h"
#include "sim/render.h"
#include "sim/simulate.h"
#include "tests/sim/sim_test_util.h"
#include "tests/support/test_support.h"

namespace mocap::sim {
namespace {

std::string example_rig(const std::string& name) {
  return test::source_dir() + "/docs/rigs/" + name + ".yaml";
}

// Renders frames of the smooth motion through the rig and checks the markers.
void check_rig_renders(const std::string& rig_name, int bits) {
  SCOPED_TRACE(rig_name + " " + std::to_string(bits) + " bit");
  SimOptions opt;
  opt.rig_path = example_rig(rig_name);
  opt.bits = bits;
  auto scene = make_scene(opt);
  ASSERT_TRUE(scene.ok()) << scene.error().message;
  auto user_rig = load_rig(opt.rig_path);
  ASSERT_TRUE(user_rig.ok());
  ASSERT_EQ(scene->rig.cameras.size(), 2u);
  EXPECT_EQ(scene->rig.cameras[0].fx, user_rig->cameras[0].fx);
  EXPECT_EQ(scene->rig.cameras[1].distortion, user_rig->cameras[1].distortion);
  MotionSpec spec;
  spec.frames = 100;
  auto plan = plan_motion(*scene, spec);
  ASSERT_TRUE(plan.ok());
  auto ws = RenderWorkspace::create(*scene);
  ASSERT_TRUE(ws.ok()) << ws.error().message;
  std::array<Image, 2> img = {make_camera_image(*scene, 0), make_camera_image(*scene, 1)};
  SceneState state = make_state(*scene);
  const double scale = static_cast<double>(scene->imaging.maxval) / 255.0;
  const double bg = scene->imaging.background_dn;
  double max_px = 0.0, max_mm = 0.0, peak = 0.0;
  int isolated = 0, triangulated = 0;
  for (int f : {0, 45, 90}) {
    apply_config(*scene, plan->configs[static_cast<std::size_t>(f)], state);
    state.noise_key = frame_noise_key(opt.seed, f);
    std::array<std::vector<MarkerView>, 2> views;
    for (int c = 0; c < 2; ++c) {
      const auto uc = static_cast<std::size_t>(c);
      ASSERT_TRUE(render(*scene, state, c, *ws, img[uc]));
      views[uc] = ws->markers;
      const ImageView v = img[uc].view();
      for (int y = 0; y < v.height; ++y)
        for (int x = 0; x < v.width; ++x) peak = std::max(peak, test::pixel_at(v, x, y));
    }
    for (int m = 0; m < scene->marker_count(); ++m) {
      const auto um = static_cast<std::size_t>(m);
      const Vec3 X = state.T_world_body[static_cast<std::size_t>(scene->marker_body[um])] *
                     scene->marker_in_body(m);
      std::array<Vec2, 2> centroid;
      std::array<bool, 2> measured{};
      for (int c = 0; c < 2; ++c) {
        const auto uc = static_cast<std::size_t>(c);
        const CameraModel& cam = scene->rig.cameras[uc];
        const MarkerView& mv = views[uc][um];
        // Every marker projects inside both images over the motion.
        Vec2 px;
        ASSERT_TRUE(project(cam, X, px)) << "frame " << f << " marker " << m;
        EXPECT_TRUE(px.x() >= 0.0 && px.y() >= 0.0 && px.x() <= cam.width - 1.0 &&
                    px.y() <= cam.height - 1.0)
            << "frame " << f << " marker " << m << " camera " << c << " at " << px.transpose();
        EXPECT_LT((mv.center_px - px).norm(), 1e-9);
        const double border = mv.disc_radius_px + 4.0;
        if (!mv.isolated() || px.x() < border || px.y() < border ||
            px.x() > cam.width - 1 - border || px.y() > cam.height - 1 - border)
          continue;
        ++isolated;
        ASSERT_TRUE(test::blob_centroid(img[uc].view(), px, bg + 30.0 * scale, bg, 2, centroid[uc]))
            << "frame " << f << " marker " << m << " camera " << c;
        const double err = (centroid[uc] - px).norm();
        // A ball's image centroid differs from the image of its centre by perspective and
        // by the lens (largest for the wide angle near the border): well under 0.25 px.
        EXPECT_LT(err, 0.25) << "frame " << f << " marker " << m << " camera " << c;
        max_px = std::max(max_px, err);
        measured[uc] = true;
      }
      if (measured[0] && measured[1]) {
        Vec3 Xt;
        ASSERT_TRUE(test::triangulate(scene->rig.cameras[0], scene->rig.cameras[1], centroid[0],
                                      centroid[1], Xt));
        max_mm = std::max(max_mm, (Xt - X).norm());
        ++triangulated;
      }
    }
  }
  std::printf(
      "rig %s (%d bit): %d isolated views, centroid max %.3f px; %d triangulated, max "
      "%.3f mm; peak %.0f DN\n",
      rig_name.c_str(), bits, isolated, max_px, triangulated, max_mm, peak);
  EXPECT_GE(isolated, 15);
  EXPECT_GE(triangulated, 6);
  EXPECT_LT(max_mm, 0.5);
  EXPECT_GT(peak, 150.0 * scale);  // the markers are bright in the output's own scale
  EXPECT_LE(peak, static_cast<double>(scene->imaging.maxval));
}

// One test per example rig (each renders 3 frames of both cameras).
TEST(SimRigs, StrongBarrelRendersTheSceneInView) { check_rig_renders("barrel", 8); }
TEST(SimRigs, PincushionRendersTheSceneInView) { check_rig_renders("pincushion", 8); }
TEST(SimRigs, OffCentrePrincipalPointsRenderTheSceneInView) { check_rig_renders("offcentre", 8); }
TEST(SimRigs, WideAngleRendersTheSceneInView) { check_rig_renders("wide", 8); }

TEST(SimRigs, SixteenBitOutputThroughAStrongLens) { check_rig_renders("barrel", 16); }

TEST(SimRigs, RecordingCarriesTheUserRig) {
  test::TempDir dir("sim_rig");
  SimOptions opt;
  opt.rig_path = example_rig("wide");
  opt.frames = 2;
  opt.threads = 1;
  auto r = write_simulated_recording(opt, dir.path() + "/rec");
  ASSERT_TRUE(r.ok()) << r.error().message;
  auto written = load_rig(dir.path() + "/rec/rig.yaml");
  ASSERT_TRUE(written.ok()) << written.error().message;
  auto given = load_rig(opt.rig_path);
  ASSERT_TRUE(given.ok());
  ASSERT_EQ(written->cameras.size(), 2u);
  for (std::size_t c = 0; c < 2; ++c) {
    EXPECT_NEAR(written->cameras[c].fx, given->cameras[c].fx, 1e-9);
    EXPECT_NEAR(written->cameras[c].cx, given->cameras[c].cx, 1e-9);
    EXPECT_NEAR(written->cameras[c].distortion[0], given->cameras[c].distortion[0], 1e-12);
    EXPECT_LT((written->cameras[c].t_cam_world - given->cameras[c].t_cam_world).norm(), 1e-6);
  }
}

// A bad rig is rejected before anything is rendered, with one line naming the file.
TEST(SimRigs, BadRigsGiveOneLineErrors) {
  test::TempDir dir("sim_badrig");
  auto base = load_rig(example_rig("pincushion"));
  ASSERT_TRUE(base.ok());
  struct Case {
    const char* name;
    Rig rig;
    const char* expect;
  };
  std::vector<Case> cases;
  {
    Rig r = *base;
    for (int c = 2; c < 33; ++c) {
      r.cameras.push_back(r.cameras[0]);
      r.cameras.back().name = "cam" + std::to_string(c);
    }
    cases.push_back({"thirty-three", r, "cameras: 33 cameras, at most 32 are supported"});
  }
  {
    Rig r = *base;  // cam1 turned round: the robot is behind it
    r.cameras[1].R_cam_world =
        Eigen::AngleAxisd(M_PI, Vec3::UnitY()).toRotationMatrix() * r.cameras[1].R_cam_world;
    r.cameras[1].t_cam_world = -r.cameras[1].R_cam_world * base->cameras[1].center_world();
    cases.push_back({"behind", r, "camera 'cam1': marker"});
  }
  {
    Rig r = *base;  // aimed 40 deg to the side: markers image outside
    r.cameras[0].R_cam_world =
        Eigen::AngleAxisd(0.7, Vec3::UnitY()).toRotationMatrix() * r.cameras[0].R_cam_world;
    r.cameras[0].t_cam_world = -r.cameras[0].R_cam_world * base->cameras[0].center_world();
    cases.push_back({"aside", r, "the scene is not in view"});
  }
  {
    Rig r = *base;  // a model that folds over inside the image
    r.cameras[0].distortion = {-0.9, 0.0, 0.0, 0.0, 0.0};
    r.cameras[0].fx = r.cameras[0].fy = 600.0;
    cases.push_back({"fold", r, "camera 'cam0': the"});
  }
  for (const Case& c : cases) {
    const std::string path = dir.file(std::string(c.name) + ".yaml");
    ASSERT_TRUE(save_rig(path, c.rig).ok());
    SimOptions opt;
    opt.rig_path = path;
    auto s = make_scene(opt);
    ASSERT_FALSE(s.ok()) << c.name;
    const std::string& msg = s.error().message;
    EXPECT_EQ(msg.rfind(path + ": ", 0), 0u) << msg;
    EXPECT_NE(msg.find(c.expect), std::string::npos) << msg;
    EXPECT_EQ(msg.find('\n'), std::string::npos) << msg;
    std::printf("%s: %s\n", c.name, msg.c_str());
  }
  SimOptions missing;
  missing.rig_path = dir.file("nope.yaml");
  auto s = make_scene(missing);
  ASSERT_FALSE(s.ok());
  EXPECT_NE(s.error().message.find("nope.yaml"), std::string::npos) << s.error().message;
}

}  // namespace
}  // namespace mocap::sim
