// Design: rendered scenes through lenses the tracker was not written against. The
// built-in shoulder scene is re-rendered with its cameras' intrinsics replaced (focal
// length, principal point, strong barrel/pincushion distortion, 8/16-bit output), and
// optionally the whole robot turned so that its markers line up along the near-
// horizontal epipolar lines of the side-by-side pair. The renderer projects every sample
// through the full camera model (undistort_pixel lattice), so the images are what such a
// lens would give. Ground truth per frame: each marker's 3D position and, per camera,
// whether its image is clean (visible, inside, unoccluded, unmerged) and how much of it
// is occluded. Also the reference used by the recall tests: blob centroids of thresholded
// components (binary moments), pairs by mutual nearest symmetric epipolar distance, and
// linear DLT — the simple pipeline reviewers compare against, written here from scratch.
#pragma once

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <string>
#include <vector>

#include "camera/camera_model.h"
#include "core/image.h"
#include "sim/motion.h"
#include "sim/render.h"
#include "sim/scene.h"
#include "sim/simulate.h"
#include "stereo/two_view.h"

namespace mocap::test {

struct Lens {
  std::string name;
  double f_scale = 1.0;                // focal length relative to the built-in lens
  std::array<double, 5> distortion{};  // k1 k2 p1 p2 k3
  Vec2 pp_shift_px = Vec2::Zero();     // principal point moved by this much
  int bits = 8;
  bool line_up = false;  // robot turned 90 deg about the depth axis: markers along rows
};

inline std::vector<Lens> test_lenses() {
  return {
      {"builtin-like", 1.0, {-0.12, 0.08, 0.0, 0.0, 0.0}, Vec2::Zero(), 8, false},
      {"strong-barrel", 1.0, {-0.38, 0.16, 0.001, -0.001, -0.03}, Vec2::Zero(), 8, false},
      {"pincushion", 1.0, {0.22, 0.05, -0.0008, 0.0006, 0.0}, Vec2::Zero(), 16, false},
      {"wide-angle", 0.6, {-0.30, 0.09, 0.0, 0.0, -0.01}, Vec2::Zero(), 8, false},
      {"off-centre-border", 1.0, {-0.2, 0.1, 0.0, 0.0, 0.0}, Vec2(330.0, -230.0), 16, false},
      // Limbs along the image rows and half the focal length: markers crowd the
      // near-horizontal epipolar lines (2 px tolerance = 4 mm at the robot).
      {"epipolar-crowding", 0.5, {-0.25, 0.1, 0.0, 0.0, 0.0}, Vec2::Zero(), 8, true},
  };
}

struct TruthMarker {
  Vec3 X_world = Vec3::Zero();
  std::array<bool, 2> clean{false, false};
  std::array<double, 2> occluded_fraction{0.0, 0.0};
  std::array<bool, 2> seen{false, false};  // in front, inside, not dropped, some area visible
  std::array<bool, 2> merged{false, false};
  bool clean_both() const { return clean[0] && clean[1]; }
};

class LensScene {
 public:
  explicit LensScene(const Lens& lens, int frames, std::uint64_t seed = 3) : lens_(lens) {
    sim::SceneOptions so;
    so.seed = seed;
    so.imaging = sim::default_imaging(lens.bits, lens.bits == 8 ? 255 : 4095);
    auto scene = sim::build_shoulder_scene(so);
    EXPECT_TRUE(scene.ok());
    scene_ = std::move(scene).value();
    for (CameraModel& cam : scene_.rig.cameras) {
      cam.fx *= lens.f_scale;
      cam.fy *= lens.f_scale;
      cam.cx += lens.pp_shift_px.x();
      cam.cy += lens.pp_shift_px.y();
      cam.distortion = lens.distortion;
    }
    auto ws = sim::RenderWorkspace::create(scene_);
    EXPECT_TRUE(ws.ok()) << lens.name << ": " << (ws.ok() ? "" : ws.error().message);
    ws_ = std::move(ws).value();
    sim::MotionSpec spec;
    spec.kind = sim::MotionKind::kSmooth;
    // The seed picks the noise and where in the motion the sequence starts.
    seed_ = seed;
    offset_ = static_cast<int>(seed % 8) * 30;
    spec.frames = frames + offset_;
    spec.seed = seed;
    auto plan = sim::plan_motion(scene_, spec);
    EXPECT_TRUE(plan.ok());
    plan_ = std::move(plan).value();
    state_ = sim::make_state(scene_);
    for (int c = 0; c < 2; ++c)
      images_[static_cast<std::size_t>(c)] = sim::make_camera_image(scene_, c);
  }

  const sim::SimScene& scene() const { return scene_; }
  int frames() const { return static_cast<int>(plan_.configs.size()) - offset_; }
  std::int64_t timestamp_ns(int f) const { return sim::frame_timestamp_ns(f, 100.0); }
  const std::vector<Iso3>& T_world_body() const { return state_.T_world_body; }

  // Renders frame f into images(); returns the truth of every marker.
  std::vector<TruthMarker> render(int f) {
    sim::JointConfig cfg = plan_.configs[static_cast<std::size_t>(f + offset_)];
    if (lens_.line_up) {
      // Turn the robot about the depth axis through its centre: limbs run along rows.
      const Vec3 c = scene_.robot_center_world;
      Iso3 T = Iso3::Identity();
      T.linear() = Eigen::AngleAxisd(1.45, Vec3::UnitY()).toRotationMatrix();
      T.translation() = c - T.linear() * c;
      cfg.T_world_robot = T * cfg.T_world_robot;
    }
    sim::apply_config(scene_, cfg, state_);
    state_.noise_key = sim::frame_noise_key(seed_, f);
    std::vector<TruthMarker> truth(static_cast<std::size_t>(scene_.marker_count()));
    for (int m = 0; m < scene_.marker_count(); ++m) {
      const int b = scene_.marker_body[static_cast<std::size_t>(m)];
      truth[static_cast<std::size_t>(m)].X_world =
          state_.T_world_body[static_cast<std::size_t>(b)] * scene_.marker_in_body(m);
    }
    for (int c = 0; c < 2; ++c) {
      EXPECT_TRUE(sim::render(scene_, state_, c, ws_, images_[static_cast<std::size_t>(c)]));
      for (int m = 0; m < scene_.marker_count(); ++m) {
        const sim::MarkerView& v = ws_.markers[static_cast<std::size_t>(m)];
        TruthMarker& t = truth[static_cast<std::size_t>(m)];
        const auto cs = static_cast<std::size_t>(c);
        t.clean[cs] = v.isolated();
        const double all = v.visible_area_px + v.occluded_area_px;
        t.occluded_fraction[cs] = all > 0.0 ? v.occluded_area_px / all : 1.0;
        t.seen[cs] = v.in_front && !v.dropped && v.inside_image && v.visible_area_px > 0.0;
        t.merged[cs] = v.merged;
      }
    }
    return truth;
  }
  ImageView view(int c) const { return images_[static_cast<std::size_t>(c)].view(); }

 private:
  Lens lens_;
  std::uint64_t seed_ = 3;
  int offset_ = 0;
  sim::SimScene scene_;
  sim::RenderWorkspace ws_;
  sim::MotionPlan plan_;
  sim::SceneState state_;
  std::array<Image, 2> images_;
};

// --- the simple reference -------------------------------------------------------------

// Binary centroids of 4-connected components above `threshold_dn` (>= min_area pixels).
inline std::vector<Vec2> reference_centroids(const ImageView& im, double threshold_dn,
                                             int min_area = 4) {
  const int w = im.width, h = im.height;
  std::vector<unsigned char> seen(static_cast<std::size_t>(w) * static_cast<std::size_t>(h), 0);
  auto at = [&](int x, int y) {
    return im.format == PixelFormat::kMono8 ? static_cast<double>(im.row8(y)[x])
                                            : static_cast<double>(im.row16(y)[x]);
  };
  std::vector<Vec2> out;
  std::vector<std::pair<int, int>> stack;
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      const auto k0 =
          static_cast<std::size_t>(y) * static_cast<std::size_t>(w) + static_cast<std::size_t>(x);
      if (seen[k0] || at(x, y) < threshold_dn) continue;
      seen[k0] = 1;
      stack.assign(1, {x, y});
      double sx = 0.0, sy = 0.0;
      int n = 0;
      bool border = false;
      while (!stack.empty()) {
        const auto [px, py] = stack.back();
        stack.pop_back();
        sx += px;
        sy += py;
        ++n;
        border = border || px == 0 || py == 0 || px == w - 1 || py == h - 1;
        for (auto [dx, dy] :
             {std::pair{1, 0}, std::pair{-1, 0}, std::pair{0, 1}, std::pair{0, -1}}) {
          const int nx = px + dx, ny = py + dy;
          if (nx < 0 || ny < 0 || nx >= w || ny >= h) continue;
          const auto k = static_cast<std::size_t>(ny) * static_cast<std::size_t>(w) +
                         static_cast<std::size_t>(nx);
          if (seen[k] || at(nx, ny) < threshold_dn) continue;
          seen[k] = 1;
          stack.emplace_back(nx, ny);
        }
      }
      if (n >= min_area && !border) out.emplace_back(sx / n, sy / n);
    }
  }
  return out;
}

// Mutual nearest symmetric epipolar distance (<= tol_px) + linear DLT.
inline std::vector<Vec3> reference_points(const Rig& rig, const std::vector<Vec2>& a,
                                          const std::vector<Vec2>& b, double tol_px = 2.0) {
  const CameraModel& c0 = rig.cameras[0];
  const CameraModel& c1 = rig.cameras[1];
  StereoGeometry g;
  if (!compute_stereo_geometry(c0, c1, g)) return {};
  std::vector<Vec2> xa(a.size()), xb(b.size());
  std::vector<bool> oka(a.size()), okb(b.size());
  for (std::size_t i = 0; i < a.size(); ++i) oka[i] = undistort_pixel(c0, a[i], xa[i]);
  for (std::size_t j = 0; j < b.size(); ++j) okb[j] = undistort_pixel(c1, b[j], xb[j]);
  auto dist = [&](std::size_t i, std::size_t j) {
    double d0 = 0.0, d1 = 0.0;
    epipolar_distances_px(g, to_scaled(c0, xa[i]), to_scaled(c1, xb[j]), d0, d1);
    return std::max(d0, d1);
  };
  std::vector<int> best_a(a.size(), -1), best_b(b.size(), -1);
  std::vector<double> da(a.size(), 1e300), db(b.size(), 1e300);
  for (std::size_t i = 0; i < a.size(); ++i) {
    for (std::size_t j = 0; j < b.size(); ++j) {
      if (!oka[i] || !okb[j]) continue;
      const double d = dist(i, j);
      if (d < da[i]) {
        da[i] = d;
        best_a[i] = static_cast<int>(j);
      }
      if (d < db[j]) {
        db[j] = d;
        best_b[j] = static_cast<int>(i);
      }
    }
  }
  std::vector<Vec3> out;
  for (std::size_t i = 0; i < a.size(); ++i) {
    const int j = best_a[i];
    if (j < 0 || best_b[static_cast<std::size_t>(j)] != static_cast<int>(i) || da[i] > tol_px)
      continue;
    Vec3 X;
    if (triangulate_dlt(g, xa[i], xb[static_cast<std::size_t>(j)], X)) out.push_back(X);
  }
  return out;
}

// Recall of clean markers (a point within 2 mm) and RMSE over the recalled ones.
struct RecallTally {
  long clean = 0;
  long recalled = 0;
  double sq_sum = 0.0;
  void add(const std::vector<TruthMarker>& truth, const std::vector<Vec3>& points) {
    for (const TruthMarker& t : truth) {
      if (!t.clean_both()) continue;
      ++clean;
      double best = 1e300;
      for (const Vec3& p : points) best = std::min(best, (p - t.X_world).squaredNorm());
      if (best <= 4.0) {
        ++recalled;
        sq_sum += best;
      }
    }
  }
  double recall() const {
    return clean ? static_cast<double>(recalled) / static_cast<double>(clean) : 0.0;
  }
  double rmse_mm() const {
    return recalled ? std::sqrt(sq_sum / static_cast<double>(recalled)) : 0.0;
  }
};

}  // namespace mocap::test
