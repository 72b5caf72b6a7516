// Renderer tests: determinism, zero allocation, exactness of the interpolated rays,
// the disc area against the analytic image of a sphere, occlusion, drop-outs, stray
// reflections and 16-bit output.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstring>
#include <numbers>

#include "sim/render.h"
#include "sim/simulate.h"
#include "tests/support/alloc_counter.h"

namespace mocap::sim {
namespace {

struct Rendered {
  SimScene scene;
  std::array<Image, 2> img;
  std::array<std::vector<MarkerView>, 2> views;
  std::array<std::vector<StrayView>, 2> strays;
  SceneState state;
};

// A scene, its motion plan and a workspace: renders frames of `motion` in both cameras.
class Renderer {
 public:
  Renderer(const SimOptions& opt, MotionKind motion, int frames) : seed_(opt.seed) {
    auto scene = make_scene(opt);
    EXPECT_TRUE(scene.ok()) << (scene.ok() ? "" : scene.error().message);
    scene_ = *scene;
    MotionSpec spec;
    spec.kind = motion;
    spec.frames = frames;
    auto plan = plan_motion(scene_, spec);
    EXPECT_TRUE(plan.ok());
    plan_ = *plan;
    auto ws = RenderWorkspace::create(scene_);
    EXPECT_TRUE(ws.ok());
    ws_ = std::move(*ws);
  }

  Rendered frame(int f) {
    Rendered r;
    r.scene = scene_;
    r.state = make_state(scene_);
    apply_config(scene_, plan_.configs[static_cast<std::size_t>(f)], r.state);
    r.state.noise_key = frame_noise_key(seed_, f);
    for (int c = 0; c < 2; ++c) {
      const auto uc = static_cast<std::size_t>(c);
      r.img[uc] = make_camera_image(scene_, c);
      EXPECT_TRUE(render(scene_, r.state, c, ws_, r.img[uc]));
      r.views[uc] = ws_.markers;
      r.strays[uc].assign(ws_.strays.begin(), ws_.strays.begin() + ws_.stray_count);
    }
    return r;
  }

 private:
  std::uint64_t seed_;
  SimScene scene_;
  MotionPlan plan_;
  RenderWorkspace ws_;
};

Rendered render_frame(const SimOptions& opt, MotionKind motion, int frames, int frame) {
  return Renderer(opt, motion, frames).frame(frame);
}

bool same_bytes(const Image& a, const Image& b) {
  return a.size_bytes() == b.size_bytes() && std::memcmp(a.data(), b.data(), a.size_bytes()) == 0;
}

int count_differing(const Image& a, const Image& b) {
  int n = 0;
  for (std::size_t i = 0; i < a.size_bytes(); ++i) n += a.data()[i] != b.data()[i];
  return n;
}

double max_pixel(const Image& im) {
  double m = 0.0;
  for (int y = 0; y < im.height(); ++y)
    for (int x = 0; x < im.width(); ++x)
      m = std::max(m, im.format() == PixelFormat::kMono8 ? double(im.view().row8(y)[x])
                                                         : double(im.view().row16(y)[x]));
  return m;
}

TEST(SimRender, DeterministicGivenTheSeed) {
  SimOptions opt;
  opt.stray = 4;
  const Rendered a = render_frame(opt, MotionKind::kSmooth, 50, 17);
  const Rendered b = render_frame(opt, MotionKind::kSmooth, 50, 17);
  EXPECT_TRUE(same_bytes(a.img[0], b.img[0]));
  EXPECT_TRUE(same_bytes(a.img[1], b.img[1]));
  opt.seed = 2;
  const Rendered c = render_frame(opt, MotionKind::kSmooth, 50, 17);
  EXPECT_FALSE(same_bytes(a.img[0], c.img[0]));
}

TEST(SimRender, SteadyStateRenderDoesNotAllocate) {
  auto scene = make_scene(SimOptions{});
  ASSERT_TRUE(scene.ok());
  auto ws = RenderWorkspace::create(*scene);
  ASSERT_TRUE(ws.ok());
  Image img = make_camera_image(*scene, 0);
  SceneState state = make_state(*scene);
  JointConfig cfg = make_config(*scene);
  cfg.q_rad[kShoulderJoint] = Vec3(-0.3, -0.4, 0.2);
  cfg.q_rad[kElbowJoint].x() = 0.9;
  ASSERT_TRUE(render(*scene, state, 0, *ws, img));  // warm-up
  test::AllocationScope scope;
  for (int i = 0; i < 3; ++i) {
    apply_config(*scene, cfg, state);
    state.noise_key = static_cast<std::uint64_t>(i);
    EXPECT_TRUE(render(*scene, state, i % 2, *ws, img));
  }
  EXPECT_EQ(scope.count(), 0u);
}

TEST(SimRender, RejectsAMismatchedImage) {
  auto scene = make_scene(SimOptions{});
  ASSERT_TRUE(scene.ok());
  auto ws = RenderWorkspace::create(*scene);
  ASSERT_TRUE(ws.ok());
  SceneState state = make_state(*scene);
  Image wrong(100, 100, PixelFormat::kMono8, 255);
  EXPECT_FALSE(render(*scene, state, 0, *ws, wrong));
  Image img = make_camera_image(*scene, 0);
  EXPECT_FALSE(render(*scene, state, 2, *ws, img));
}

TEST(SimRender, InterpolatedRaysMatchUndistortPixel) {
  auto scene = make_scene(SimOptions{});
  ASSERT_TRUE(scene.ok());
  auto ws = RenderWorkspace::create(*scene);
  ASSERT_TRUE(ws.ok());
  double worst_px = 0.0;
  for (int c = 0; c < 2; ++c) {
    const CameraModel& cam = scene->rig.cameras[static_cast<std::size_t>(c)];
    const auto& lat = ws->lattices[static_cast<std::size_t>(c)];
    for (int k = 0; k < 2000; ++k) {
      // Points spread over the whole image, including the corners.
      const double u = std::fmod(k * 7.31 + 0.123, cam.width - 1.0);
      const double v = std::fmod(k * 3.77 + 0.456, cam.height - 1.0);
      const int i = static_cast<int>(std::floor(u + 0.5)),
                j = static_cast<int>(std::floor(v + 0.5));
      const double fu = u + 0.5 - i, fv = v + 0.5 - j;
      const auto w1 = static_cast<std::size_t>(cam.width + 1);
      const std::size_t c00 = static_cast<std::size_t>(j) * w1 + static_cast<std::size_t>(i);
      auto lerp2 = [&](const std::vector<double>& a) {
        const double l = a[c00] + fv * (a[c00 + w1] - a[c00]);
        const double r = a[c00 + 1] + fv * (a[c00 + w1 + 1] - a[c00 + 1]);
        return l + fu * (r - l);
      };
      Vec2 exact;
      ASSERT_TRUE(undistort_pixel(cam, Vec2(u, v), exact));
      const Vec2 interp(lerp2(lat.xn), lerp2(lat.yn));
      // Distance in pixels: re-project both.
      worst_px = std::max(worst_px, (normalized_to_pixel(cam, interp) - Vec2(u, v)).norm());
    }
  }
  EXPECT_LT(worst_px, 1e-4);
}

TEST(SimRender, DiscAreaMatchesTheAnalyticImageOfTheSphere) {
  SimOptions opt;
  opt.bits = 16;
  opt.maxval = 65535;
  opt.noise_dn = 0.0;
  opt.blur_px = 0.0;
  auto scene = make_scene(opt);
  ASSERT_TRUE(scene.ok());
  scene->imaging.shot_gain_dn_per_e = 0.0;
  scene->imaging.limb_factor = 1.0;  // uniform disc: sum of signal / peak = area
  auto ws = RenderWorkspace::create(*scene);
  ASSERT_TRUE(ws.ok());
  SceneState state = make_state(*scene);
  Image img = make_camera_image(*scene, 0);
  int checked = 0;
  for (int c = 0; c < 2; ++c) {
    const CameraModel& cam = scene->rig.cameras[static_cast<std::size_t>(c)];
    ASSERT_TRUE(render(*scene, state, c, *ws, img));
    for (int m = 0; m < scene->marker_count(); ++m) {
      const MarkerView& mv = ws->markers[static_cast<std::size_t>(m)];
      if (!mv.isolated()) continue;
      const Vec3& C = ws->sphere_c[static_cast<std::size_t>(m)];
      const double peak = ws->sphere_peak[static_cast<std::size_t>(m)];
      ASSERT_LT(peak, scene->imaging.maxval - scene->imaging.background_dn);
      double sum = 0.0;
      const int r = static_cast<int>(std::ceil(mv.disc_radius_px)) + 3;
      for (int y = static_cast<int>(mv.center_px.y()) - r;
           y <= static_cast<int>(mv.center_px.y()) + r; ++y)
        for (int x = static_cast<int>(mv.center_px.x()) - r;
             x <= static_cast<int>(mv.center_px.x()) + r; ++x)
          sum += img.view().row16(y)[x] - scene->imaging.background_dn;
      const double area_img = sum / peak;
      // Analytic: the cone of half-angle alpha around the centre's direction cut by
      // z = 1 is an ellipse; scale by the pixel Jacobian of the lens at its centre.
      const double D = C.norm();
      const double sa = scene->marker_radius_mm / D;
      const double ca = std::sqrt(1.0 - sa * sa);
      const double ct = C.z() / D;
      const double den = ct * ct - sa * sa;
      const double a = sa * ca / den, b = sa / std::sqrt(den);
      const Vec2 xn(C.x() / C.z(), C.y() / C.z());
      const double area_true =
          std::numbers::pi * a * b * cam.fx * cam.fy * distort_jacobian(cam, xn).determinant();
      EXPECT_NEAR(area_img / area_true, 1.0, 0.02) << "marker " << m;
      EXPECT_NEAR(mv.visible_area_px / area_true, 1.0, 0.02) << "marker " << m;
      ++checked;
    }
  }
  EXPECT_GE(checked, 10);
}

TEST(SimRender, LimbsHideMarkersInSomePosesAndTheTruthSaysSo) {
  SimOptions opt;
  int occluded = 0, hidden_checked = 0;
  Renderer renderer(opt, MotionKind::kPoses, 44);
  for (int f = 0; f < 44; f += 2) {
    const Rendered r = renderer.frame(f);
    for (int c = 0; c < 2; ++c) {
      for (const MarkerView& mv : r.views[static_cast<std::size_t>(c)]) {
        if (!mv.in_front || mv.occluded_area_px <= 0.0) continue;
        ++occluded;
        EXPECT_FALSE(mv.isolated());
        if (mv.visible_area_px == 0.0 && mv.inside_image) {
          // Fully hidden by a dark limb or base: nothing bright at its projection (a ball
          // hidden behind another ball shows that ball there instead: not checked).
          bool behind_ball = false;
          for (const MarkerView& other : r.views[static_cast<std::size_t>(c)]) {
            if (&other != &mv && other.visible_area_px > 0.0 &&
                (other.disc_center_px - mv.center_px).norm() < other.disc_radius_px + 3.0)
              behind_ball = true;
          }
          if (behind_ball) continue;
          const int x = static_cast<int>(std::lround(mv.center_px.x())),
                    y = static_cast<int>(std::lround(mv.center_px.y()));
          EXPECT_LT(r.img[static_cast<std::size_t>(c)].view().row8(y)[x],
                    r.scene.imaging.background_dn + 20.0);
          ++hidden_checked;
        }
      }
    }
  }
  EXPECT_GT(occluded, 0);
  std::printf("occlusion: %d occluded marker views, %d fully hidden\n", occluded, hidden_checked);
}

TEST(SimRender, DropoutRemovesMarkers) {
  SimOptions opt;
  opt.dropout = 1.0;
  const Rendered all = render_frame(opt, MotionKind::kSmooth, 20, 3);
  for (int c = 0; c < 2; ++c) {
    for (const MarkerView& mv : all.views[static_cast<std::size_t>(c)]) EXPECT_TRUE(mv.dropped);
    EXPECT_LT(max_pixel(all.img[static_cast<std::size_t>(c)]),
              all.scene.imaging.background_dn + 20.0);
  }
  opt.dropout = 0.3;
  int dropped = 0, total = 0;
  Renderer renderer(opt, MotionKind::kSmooth, 20);
  for (int f = 0; f < 20; ++f) {
    const Rendered r = renderer.frame(f);
    for (const auto& views : r.views) {
      for (const MarkerView& mv : views) {
        dropped += mv.dropped;
        ++total;
      }
    }
  }
  EXPECT_NEAR(static_cast<double>(dropped) / total, 0.3, 0.06);
}

TEST(SimRender, StrayReflectionsAddBrightBlobsOnlyWhereTheTruthSays) {
  SimOptions opt;
  const Rendered base = render_frame(opt, MotionKind::kSmooth, 20, 5);
  opt.stray = 12;
  const Rendered glints = render_frame(opt, MotionKind::kSmooth, 20, 5);
  int drawn = 0;
  for (int c = 0; c < 2; ++c) {
    const auto uc = static_cast<std::size_t>(c);
    EXPECT_GT(count_differing(base.img[uc], glints.img[uc]), 0);
    for (const StrayView& s : glints.strays[uc]) {
      ASSERT_EQ(s.kind, StrayKind::kGlint);
      const int x = static_cast<int>(std::lround(s.px.x())),
                y = static_cast<int>(std::lround(s.px.y()));
      if (x < 2 || y < 2 || x >= 1030 || y >= 774 || s.peak_dn < 60.0) continue;
      int brightest = 0;
      for (int dy = -2; dy <= 2; ++dy)
        for (int dx = -2; dx <= 2; ++dx)
          brightest = std::max<int>(brightest, glints.img[uc].view().row8(y + dy)[x + dx]);
      EXPECT_GT(brightest, base.scene.imaging.background_dn + 0.3 * s.peak_dn);
      ++drawn;
    }
  }
  EXPECT_GT(drawn, 0);
  opt.stray = 0;
  opt.streak = true;
  const Rendered streak = render_frame(opt, MotionKind::kSmooth, 20, 5);
  int streak_points = 0;
  for (const auto& s : streak.strays) streak_points += static_cast<int>(s.size());
  EXPECT_GT(streak_points, 10);
  EXPECT_GT(
      count_differing(base.img[0], streak.img[0]) + count_differing(base.img[1], streak.img[1]),
      200);
}

TEST(SimRender, SixteenBitOutput) {
  SimOptions opt;
  opt.bits = 16;
  const Rendered r = render_frame(opt, MotionKind::kSmooth, 20, 4);
  for (const Image& im : r.img) {
    EXPECT_EQ(im.format(), PixelFormat::kMono16);
    EXPECT_EQ(im.maxval(), 4095);
    const double m = max_pixel(im);
    EXPECT_LE(m, 4095.0);
    EXPECT_GT(m, 0.6 * 175.0 * 4095.0 / 255.0);  // marker discs at the 12-bit scale
  }
}

}  // namespace
}  // namespace mocap::sim
