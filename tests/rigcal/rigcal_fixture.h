// Design: synthetic wand observations for the rig calibration tests: the simulator's
// true rig, a wand moved on the simulator's path, and its markers projected through
// the true cameras with Gaussian pixel noise (no rendering: fast under sanitizers).
#pragma once

#include <random>

#include "formats/wand_yaml.h"
#include "rigcal/rig_calibrator.h"
#include "sim/scene.h"
#include "sim/simulate.h"
#include "sim/wand_sim.h"

namespace mocap::test {

// The test wand: three balls at 0, 110 and 300 mm along the bar.
inline WandSpec test_wand() {
  WandSpec w;
  w.markers_mm = {0.0, 110.0, 300.0};
  return w;
}

// The paper's pair about 1 m from the robot (the stalks scene's mount), for which these
// tests' tolerances were set.
inline std::array<CameraModel, 2> true_cameras() {
  sim::SimOptions o;
  o.scene = sim::SceneKind::kStalks;
  auto scene = sim::make_scene(o);
  return {scene->rig.cameras[0], scene->rig.cameras[1]};
}

// The cameras re-expressed with camera 0 as world.
inline std::array<CameraModel, 2> cam0_world(std::array<CameraModel, 2> cams) {
  const Iso3 T_world_cam0 = cams[0].T_cam_world().inverse();
  for (CameraModel& c : cams) {
    const Iso3 T = c.T_cam_world() * T_world_cam0;
    c.R_cam_world = T.linear();
    c.t_cam_world = T.translation();
  }
  return cams;
}

// Blobs per frame: the wand's projections (+ noise) where inside the image, plus
// `strays` random points per image.
inline rigcal::FrameBlobs synthetic_wand_blobs(const std::array<CameraModel, 2>& cams,
                                               const WandSpec& wand, int frames, double noise_px,
                                               int strays, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> noise(0.0, noise_px);
  std::uniform_real_distribution<double> ux(0.0, 1.0);
  rigcal::FrameBlobs out(static_cast<std::size_t>(frames));
  const double mid = 0.5 * (wand.markers_mm.front() + wand.markers_mm.back());
  for (int f = 0; f < frames; ++f) {
    const Iso3 T = sim::wand_pose(f, frames, seed);
    for (std::size_t c = 0; c < 2; ++c) {
      for (double s : wand.markers_mm) {
        Vec2 px;
        if (!project(cams[c], T * Vec3(s - mid, 0, 0), px)) continue;
        px += Vec2(noise(rng), noise(rng));
        if (px.x() < 5 || px.y() < 5 || px.x() > cams[c].width - 6 || px.y() > cams[c].height - 6)
          continue;
        out[static_cast<std::size_t>(f)][c].push_back(px);
      }
      for (int k = 0; k < strays; ++k) {
        out[static_cast<std::size_t>(f)][c].push_back(
            Vec2(ux(rng) * cams[c].width, ux(rng) * cams[c].height));
      }
    }
  }
  return out;
}

}  // namespace mocap::test
