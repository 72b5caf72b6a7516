// The simulator's acceptance test ("honesty"): isolated rendered markers, measured the
// way a detector would measure them (threshold, connected region, background-subtracted
// intensity-weighted centroid), must lie within 0.05 px of project() of the true sphere
// centre, and triangulating both cameras' centroids with the true rig must land within
// 0.1 mm of the true marker. Runs over several frames of the smooth motion at the
// default noise, and prints the max and RMS errors.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "sim/render.h"
#include "sim/simulate.h"
#include "tests/sim/sim_test_util.h"

namespace mocap::sim {
namespace {

// The renderer is the same in both scenes; this checks it at the paper's geometry (the
// stalks pair, markers about 1 m away, 15 px discs), where its thresholds were set.
TEST(SimHonesty, CentroidsAndTriangulationMatchTheTruth) {
  SimOptions opt;  // defaults: 8 bits, noise 1.5 DN, blur 0.5 px
  opt.scene = SceneKind::kStalks;
  auto scene = make_scene(opt);
  ASSERT_TRUE(scene.ok()) << scene.error().message;
  MotionSpec spec;
  spec.frames = 100;
  auto plan = plan_motion(*scene, spec);
  ASSERT_TRUE(plan.ok());
  auto ws = RenderWorkspace::create(*scene);
  ASSERT_TRUE(ws.ok());
  std::array<Image, 2> img = {make_camera_image(*scene, 0), make_camera_image(*scene, 1)};
  SceneState state = make_state(*scene);
  const double bg = scene->imaging.background_dn;
  const double threshold = bg + 30.0;

  double max_px = 0.0, sum2_px = 0.0, max_mm = 0.0, sum2_mm = 0.0;
  int n_px = 0, n_mm = 0;
  for (int f = 0; f < 100; f += 7) {
    apply_config(*scene, plan->configs[static_cast<std::size_t>(f)], state);
    state.noise_key = frame_noise_key(opt.seed, f);
    std::array<std::vector<MarkerView>, 2> views;
    for (int c = 0; c < 2; ++c) {
      ASSERT_TRUE(render(*scene, state, c, *ws, img[static_cast<std::size_t>(c)]));
      views[static_cast<std::size_t>(c)] = ws->markers;
    }
    for (int m = 0; m < scene->marker_count(); ++m) {
      std::array<Vec2, 2> centroid;
      std::array<bool, 2> ok{};
      for (int c = 0; c < 2; ++c) {
        const MarkerView& mv = views[static_cast<std::size_t>(c)][static_cast<std::size_t>(m)];
        const CameraModel& cam = scene->rig.cameras[static_cast<std::size_t>(c)];
        const double border = mv.disc_radius_px + 4.0;
        if (!mv.isolated() || mv.center_px.x() < border || mv.center_px.y() < border ||
            mv.center_px.x() > cam.width - 1 - border || mv.center_px.y() > cam.height - 1 - border)
          continue;
        Vec2 cen;
        ASSERT_TRUE(test::blob_centroid(img[static_cast<std::size_t>(c)].view(), mv.center_px,
                                        threshold, bg, 2, cen))
            << "frame " << f << " marker " << m << " camera " << c;
        const double err = (cen - mv.center_px).norm();
        EXPECT_LT(err, 0.05) << "frame " << f << " marker " << m << " camera " << c;
        max_px = std::max(max_px, err);
        sum2_px += err * err;
        ++n_px;
        centroid[static_cast<std::size_t>(c)] = cen;
        ok[static_cast<std::size_t>(c)] = true;
      }
      if (!ok[0] || !ok[1]) continue;
      Vec3 X;
      ASSERT_TRUE(test::triangulate(scene->rig.cameras[0], scene->rig.cameras[1], centroid[0],
                                    centroid[1], X));
      const Vec3 X_true = state.T_world_body[static_cast<std::size_t>(
                              scene->marker_body[static_cast<std::size_t>(m)])] *
                          scene->marker_in_body(m);
      const double err = (X - X_true).norm();
      EXPECT_LT(err, 0.1) << "frame " << f << " marker " << m;
      max_mm = std::max(max_mm, err);
      sum2_mm += err * err;
      ++n_mm;
    }
  }
  ASSERT_GE(n_px, 100) << "too few isolated markers to judge";
  ASSERT_GE(n_mm, 40);
  std::printf(
      "honesty: %d centroids: max %.4f px, rms %.4f px; %d points: max %.4f mm, rms %.4f mm\n",
      n_px, max_px, std::sqrt(sum2_px / n_px), n_mm, max_mm, std::sqrt(sum2_mm / n_mm));
}

}  // namespace
}  // namespace mocap::sim
