// Design: see scene_rig.h. The fold test samples the radial mapping at 400 radii out to
// 1.05 x the farthest image corner's undistorted radius (tangential terms are small
// corrections and are covered by the round-trip test at every marker).
#include "sim/scene_rig.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "sim/scene.h"
#include "sim/scene_cameras.h"

namespace mocap::sim {
namespace {

std::string fmt(double v) {
  char buf[32];
  std::snprintf(buf, sizeof(buf), "%.1f", v);
  return buf;
}

std::string fmt3(double v) {
  char buf[32];
  std::snprintf(buf, sizeof(buf), "%.3f", v);
  return buf;
}

Expected<void> check_lens(const CameraModel& cam, const std::string& source,
                          const std::string& where) {
  double r_max = 0.0;
  const double w = cam.width - 0.5;
  const double h = cam.height - 0.5;
  for (const Vec2& corner : {Vec2(-0.5, -0.5), Vec2(w, -0.5), Vec2(-0.5, h), Vec2(w, h)}) {
    Vec2 xn;
    if (!undistort_pixel(cam, corner, xn)) {
      return make_error(source, where,
                        "the distortion cannot be inverted at the image corner (" +
                            fmt(corner.x()) + ", " + fmt(corner.y()) + "): not a physical lens");
    }
    r_max = std::max(r_max, xn.norm());
  }
  const auto& k = cam.distortion;
  constexpr int kSteps = 400;
  for (int i = 1; i <= kSteps; ++i) {
    const double r = 1.05 * r_max * i / kSteps;
    const double r2 = r * r;
    // d/dr [r (1 + k1 r^2 + k2 r^4 + k3 r^6)]
    const double slope = 1.0 + 3.0 * k[0] * r2 + 5.0 * k[1] * r2 * r2 + 7.0 * k[4] * r2 * r2 * r2;
    if (!(slope > 0.0)) {
      return make_error(source, where,
                        "the radial distortion folds over at normalised radius " + fmt3(r) +
                            " (the image reaches " + fmt3(r_max) +
                            "): two directions would image onto one pixel");
    }
  }
  return {};
}

}  // namespace

Expected<void> check_rig_for_scene(const Rig& rig, const SimScene& scene,
                                   const std::string& source) {
  const auto n = static_cast<int>(rig.cameras.size());
  if (n < kMinSimCameras || n > kMaxSimCameras) {
    return make_error(source, "cameras",
                      "the simulator renders " + std::to_string(kMinSimCameras) + " to " +
                          std::to_string(kMaxSimCameras) + " cameras, the rig has " +
                          std::to_string(n));
  }
  for (std::size_t c = 0; c < rig.cameras.size(); ++c) {  // names are the frame folders
    for (std::size_t d = 0; d < c; ++d) {
      if (rig.cameras[c].name == rig.cameras[d].name)
        return make_error(source, "camera '" + rig.cameras[c].name + "'",
                          "listed twice (the name is its recording folder)");
    }
    if (rig.cameras[c].name.empty() || rig.cameras[c].name == "gt" ||
        rig.cameras[c].name.find('/') != std::string::npos)
      return make_error(source, "camera " + std::to_string(c),
                        "name '" + rig.cameras[c].name +
                            "' cannot be a recording folder (empty, 'gt' or with '/')");
  }
  for (std::size_t c = 0; c < rig.cameras.size(); ++c) {
    const CameraModel& cam = rig.cameras[c];
    const std::string where = "camera '" + cam.name + "'";
    if (cam.width < 16 || cam.height < 16 || cam.width > 8192 || cam.height > 8192)
      return make_error(source, where, "image size must be 16..8192 px for the simulator");
    if (auto r = check_lens(cam, source, where); !r) return r;
    for (int m = 0; m < scene.marker_count(); ++m) {
      const auto um = static_cast<std::size_t>(m);
      const auto b = static_cast<std::size_t>(scene.marker_body[um]);
      const std::string marker = "marker " + std::to_string(scene.marker_index[um]) + " of '" +
                                 scene.targets.bodies[b].name + "'";
      const Vec3 X = scene.T_world_body_ref[b] * scene.marker_in_body(m);
      const Vec3 X_cam = cam.R_cam_world * X + cam.t_cam_world;
      Vec2 px;
      if (!(X_cam.z() > scene.marker_radius_mm) || !project(cam, X, px)) {
        return make_error(source, where,
                          marker +
                              " is behind the camera at the reference pose: the scene "
                              "is not in view");
      }
      if (!(px.x() >= 0.0 && px.y() >= 0.0 && px.x() <= cam.width - 1.0 &&
            px.y() <= cam.height - 1.0)) {
        return make_error(source, where,
                          marker + " images at (" + fmt(px.x()) + ", " + fmt(px.y()) +
                              "), outside the " + std::to_string(cam.width) + "x" +
                              std::to_string(cam.height) +
                              " image at the reference pose: the scene is not in view");
      }
      Vec2 xn;
      const Vec2 xn_true(X_cam.x() / X_cam.z(), X_cam.y() / X_cam.z());
      if (!undistort_pixel(cam, px, xn) || (xn - xn_true).norm() > 1e-6) {
        return make_error(source, where,
                          "the lens model folds over at " + marker +
                              " (its pixel does not invert back onto its ray)");
      }
    }
  }
  return {};
}

}  // namespace mocap::sim
