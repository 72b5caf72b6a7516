// Design: synthetic wand observations for the rig calibration tests: the simulator's
// true rig, a wand moved on the simulator's path, and its markers projected through
// the true cameras with Gaussian pixel noise (no rendering: fast under sanitizers), all
// by one generator (wand_blobs) along a path: the simulator's (synthetic_wand_blobs) or,
// for rigs of more than two cameras, random poses in front of a robot seen by a ring of
// cameras (ring_cameras, ring_wand_blobs), hidden from a camera at random.
#pragma once

#include <cmath>
#include <functional>
#include <random>
#include <string>
#include <vector>

#include "formats/wand_yaml.h"
#include "rigcal/rig_calibrator.h"
#include "sim/scene.h"
#include "sim/simulate.h"
#include "sim/wand_sim.h"

namespace mocap::test {

// Angle of the rotation between two rotation matrices (degrees).
inline double rotation_error_deg(const Mat3& a, const Mat3& b) {
  return Eigen::AngleAxisd(a * b.transpose()).angle() * 180.0 / 3.14159265358979323846;
}

// The test wand: three balls at 0, 110 and 300 mm along the bar.
inline WandSpec test_wand() {
  WandSpec w;
  w.markers_mm = {0.0, 110.0, 300.0};
  return w;
}

// The paper's pair about 1 m from the robot (the stalks scene's mount), for which these
// tests' tolerances were set.
inline std::vector<CameraModel> true_cameras() {
  sim::SimOptions o;
  o.scene = sim::SceneKind::kStalks;
  auto scene = sim::make_scene(o);
  return {scene->rig.cameras[0], scene->rig.cameras[1]};
}

// The cameras re-expressed with camera 0 as world.
inline std::vector<CameraModel> cam0_world(std::vector<CameraModel> cams) {
  const Iso3 T_world_cam0 = cams[0].T_cam_world().inverse();
  for (CameraModel& c : cams) {
    const Iso3 T = c.T_cam_world() * T_world_cam0;
    c.R_cam_world = T.linear();
    c.t_cam_world = T.translation();
  }
  return cams;
}

// n cameras on a ring around a robot standing at the origin (Z up): 2.0..3.0 m from
// the Z axis, at heights 1.2..2.4 m, each looking at (0, 0, 900); the intrinsics of
// the simulator's camera 0. World = the robot's frame.
inline std::vector<CameraModel> ring_cameras(int n) {
  const CameraModel base = true_cameras()[0];
  std::vector<CameraModel> out;
  const Vec3 target(0.0, 0.0, 900.0), up = Vec3::UnitZ();
  for (int i = 0; i < n; ++i) {
    const double az = 2.0 * 3.14159265358979323846 * i / n + 0.3 * std::sin(1.7 * i);
    const double radius = 2000.0 + 1000.0 * ((i * 37) % 11) / 10.0;
    const double height = 1200.0 + 1200.0 * ((i * 5) % 7) / 6.0;
    const Vec3 C(radius * std::cos(az), radius * std::sin(az), height);
    const Vec3 z = (target - C).normalized();
    const Vec3 x = z.cross(up).normalized();
    const Vec3 y = z.cross(x);
    CameraModel cam = base;
    cam.name = "cam" + std::to_string(i);
    cam.R_cam_world.row(0) = x.transpose();
    cam.R_cam_world.row(1) = y.transpose();
    cam.R_cam_world.row(2) = z.transpose();
    cam.t_cam_world = -cam.R_cam_world * C;
    out.push_back(cam);
  }
  return out;
}

// The wand (marker 0 at -mid along its axis) at a random pose: centre in a
// 900 x 900 x 700 mm box around (0, 0, 900), direction uniform on the sphere.
inline Iso3 ring_wand_pose(std::mt19937_64& rng) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  Vec3 dir;
  do {
    dir = Vec3(u(rng), u(rng), u(rng));
  } while (dir.norm() > 1.0 || dir.norm() < 0.1);
  dir.normalize();
  const Vec3 centre(450.0 * u(rng), 450.0 * u(rng), 900.0 + 350.0 * u(rng));
  const Vec3 any = std::fabs(dir.z()) < 0.9 ? Vec3::UnitZ() : Vec3::UnitX();
  const Vec3 y = dir.cross(any).normalized();
  Mat3 R;
  R.col(0) = dir;
  R.col(1) = y;
  R.col(2) = dir.cross(y);
  return make_iso(R, centre);
}

// Where the wand is in frame f (marker 0 at -mid along its axis), drawn from rng or not.
using WandPath = std::function<Iso3(int f, std::mt19937_64& rng)>;

// The one generator of wand blobs: per frame the wand's pose from `path`; per camera the
// whole wand hidden with probability p_hidden (the robot in the way; drawn only when
// p_hidden > 0); each marker projected with Gaussian noise of noise_px per axis, kept
// when at least 5 px inside the image; then `strays` random points per image.
inline rigcal::FrameBlobs wand_blobs(const std::vector<CameraModel>& cams, const WandSpec& wand,
                                     int frames, const WandPath& path, double noise_px,
                                     double p_hidden, int strays, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  // Drawn also without noise (noise_px = 0), so the draws stay those of any noise.
  std::normal_distribution<double> noise(0.0, noise_px > 0.0 ? noise_px : 1.0);
  std::uniform_real_distribution<double> u01(0.0, 1.0);
  rigcal::FrameBlobs out(static_cast<std::size_t>(frames),
                         std::vector<std::vector<Vec2>>(cams.size()));
  const double mid = 0.5 * (wand.markers_mm.front() + wand.markers_mm.back());
  for (int f = 0; f < frames; ++f) {
    const Iso3 T = path(f, rng);
    auto& frame = out[static_cast<std::size_t>(f)];
    for (std::size_t c = 0; c < cams.size(); ++c) {
      const bool hidden = p_hidden > 0.0 && u01(rng) < p_hidden;
      for (double s : wand.markers_mm) {
        Vec2 px;
        if (!project(cams[c], T * Vec3(s - mid, 0, 0), px)) continue;
        const Vec2 n(noise(rng), noise(rng));
        if (noise_px > 0.0) px += n;
        if (hidden || px.x() < 5 || px.y() < 5 || px.x() > cams[c].width - 6 ||
            px.y() > cams[c].height - 6)
          continue;
        frame[c].push_back(px);
      }
      for (int k = 0; k < strays; ++k)
        frame[c].push_back(Vec2(u01(rng) * cams[c].width, u01(rng) * cams[c].height));
    }
  }
  return out;
}

// The pair's wand on the simulator's path (sim::wand_pose), with `strays` random
// points per image.
inline rigcal::FrameBlobs synthetic_wand_blobs(const std::vector<CameraModel>& cams,
                                               const WandSpec& wand, int frames, double noise_px,
                                               int strays, std::uint64_t seed) {
  const WandPath path = [&](int f, std::mt19937_64&) { return sim::wand_pose(f, frames, seed); };
  return wand_blobs(cams, wand, frames, path, noise_px, 0.0, strays, seed);
}

// A ring rig's wand at random poses in front of the robot (ring_wand_pose), hidden from
// each camera with probability p_hidden.
inline rigcal::FrameBlobs ring_wand_blobs(const std::vector<CameraModel>& cams,
                                          const WandSpec& wand, int frames, double noise_px,
                                          double p_hidden, std::uint64_t seed) {
  const WandPath path = [](int, std::mt19937_64& rng) { return ring_wand_pose(rng); };
  return wand_blobs(cams, wand, frames, path, noise_px, p_hidden, 0, seed);
}

}  // namespace mocap::test
