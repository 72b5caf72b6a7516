// Test fixtures shared by the stereo tests and benchmarks: the paper's rig (two
// 1032x776 cameras, f ~ 1290 px, 477 mm baseline, verged toward a point 1 m ahead), a
// 4-camera ring, and helpers to place cameras by look-at.
#pragma once

#include <cmath>
#include <random>
#include <string>

#include "camera/camera_model.h"

namespace mocap::test {

// A camera at centre C_world looking at target_world, x axis ~ world x, y down.
inline CameraModel look_at_camera(const std::string& name, const Vec3& C_world,
                                  const Vec3& target_world, double f_px,
                                  std::array<double, 5> distortion) {
  CameraModel c;
  c.name = name;
  c.width = 1032;
  c.height = 776;
  c.fx = f_px;
  c.fy = f_px;
  c.cx = 515.5;
  c.cy = 387.5;
  c.distortion = distortion;
  const Vec3 z = (target_world - C_world).normalized();
  Vec3 down(0.0, 1.0, 0.0);
  if (std::abs(z.dot(down)) > 0.99) down = Vec3(0.0, 0.0, 1.0);
  const Vec3 x = down.cross(z).normalized();
  const Vec3 y = z.cross(x);
  c.R_cam_world.row(0) = x.transpose();
  c.R_cam_world.row(1) = y.transpose();
  c.R_cam_world.row(2) = z.transpose();
  c.t_cam_world = -c.R_cam_world * C_world;
  return c;
}

// World origin midway between the cameras, z toward the scene, cameras verged toward
// (0, 0, 1000) mm.
inline Rig paper_rig(double baseline_mm = 477.0) {
  Rig rig;
  const Vec3 target(0.0, 0.0, 1000.0);
  rig.cameras.push_back(look_at_camera("cam0", Vec3(-0.5 * baseline_mm, 0.0, 0.0), target, 1290.3,
                                       {-0.12, 0.09, 0.0005, -0.0003, -0.01}));
  rig.cameras.push_back(look_at_camera("cam1", Vec3(0.5 * baseline_mm, 0.0, 0.0), target, 1288.7,
                                       {-0.11, 0.085, -0.0004, 0.0002, -0.008}));
  rig.cameras[1].fy = 1289.9;
  rig.cameras[1].cx = 517.2;
  rig.cameras[1].cy = 385.9;
  return rig;
}

// Four cameras on a 120-degree arc of radius 1.4 m around (0, 0, 1000) mm, at two
// heights, each with its own focal length and distortion (a multi-camera rig).
inline Rig ring_rig() {
  Rig rig;
  const Vec3 target(0.0, 0.0, 1000.0);
  const double r = 1400.0;
  const double f[4] = {1290.0, 1100.0, 1450.0, 1200.0};
  const std::array<double, 5> d[4] = {{-0.12, 0.09, 0.0005, -0.0003, -0.01},
                                      {-0.25, 0.12, 0.0, 0.0, -0.02},
                                      {0.05, -0.02, 0.0, 0.0, 0.0},
                                      {-0.18, 0.05, 0.0002, 0.0004, 0.0}};
  for (int k = 0; k < 4; ++k) {
    const double a = (-60.0 + 40.0 * k) * M_PI / 180.0;  // a 120 degree arc
    const Vec3 C = target + Vec3(r * std::sin(a), -300.0 + 150.0 * (k % 2), -r * std::cos(a));
    rig.cameras.push_back(look_at_camera("cam" + std::to_string(k), C, target, f[k], d[k]));
  }
  return rig;
}

inline bool in_image(const CameraModel& c, const Vec2& px) {
  return px.x() >= 0.0 && px.y() >= 0.0 && px.x() <= c.width - 1.0 && px.y() <= c.height - 1.0;
}

// A random point in the working volume visible in both cameras (and its pixels).
inline Vec3 random_visible_point(const Rig& rig, std::mt19937& rng, Vec2& px0, Vec2& px1,
                                 double z_min = 700.0, double z_max = 1400.0) {
  std::uniform_real_distribution<double> ux(-350.0, 350.0), uy(-250.0, 250.0), uz(z_min, z_max);
  for (;;) {
    const Vec3 X(ux(rng), uy(rng), uz(rng));
    if (project(rig.cameras[0], X, px0) && project(rig.cameras[1], X, px1) &&
        in_image(rig.cameras[0], px0) && in_image(rig.cameras[1], px1))
      return X;
  }
}

}  // namespace mocap::test
