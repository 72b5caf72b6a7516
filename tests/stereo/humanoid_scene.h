// Test fixtures shared by the stereo index tests and benchmarks: "the whole robot", a ring
// of 2..8 cameras (1280x1024, f ~ 1250 px, mild distortion) about 3 m around a humanoid
// working volume, and random frames of markers in that volume with 0.1 px centroid noise,
// views missing at random (occlusion) or hidden by the body (markers on its surface),
// stray blobs and, optionally, split blobs (two
// blobs close together where one marker was expected) and exact duplicate blobs. The
// property tests draw their many scenes with random_ring_rig() and random_scene().
#pragma once

#include <algorithm>
#include <cmath>
#include <random>
#include <string>
#include <vector>

#include "tests/stereo/stereo_test_rig.h"

namespace mocap::test {

struct RingOptions {
  int cameras = 8;
  double radius_mm = 3000.0;
  double jitter_deg = 0.0;  // random offset of each camera's angle on the ring
};

// Cameras evenly spaced on a ring about the vertical (world y, down) axis through the
// origin, at heights between 0.4 m and 1.2 m above the volume's centre, looking at it.
inline Rig humanoid_ring_rig(const RingOptions& o, std::mt19937& rng) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  Rig rig;
  for (int k = 0; k < o.cameras; ++k) {
    const double a = (2.0 * M_PI * k) / o.cameras + o.jitter_deg * M_PI / 180.0 * u(rng);
    const double height = -800.0 - 400.0 * std::cos(3.0 * k);
    const Vec3 C(o.radius_mm * std::sin(a), height, o.radius_mm * std::cos(a));
    const double f = 1250.0 * (1.0 + 0.03 * u(rng));
    CameraModel cam = look_at_camera(
        "cam" + std::to_string(k), C, Vec3(0.0, -100.0, 0.0), f,
        {-0.10 + 0.03 * u(rng), 0.05 * u(rng), 0.0003 * u(rng), 0.0003 * u(rng), 0.0});
    cam.width = 1280;
    cam.height = 1024;
    cam.cx = 639.5 + 4.0 * u(rng);
    cam.cy = 511.5 + 4.0 * u(rng);
    cam.fy = cam.fx * (1.0 + 0.001 * u(rng));
    rig.cameras.push_back(cam);
  }
  return rig;
}

struct SceneOptions {
  int markers = 70;
  Vec3 half_extent_mm = Vec3(300.0, 900.0, 300.0);  // humanoid: 0.6 x 1.8 x 0.6 m
  int strays = 4;                                   // per camera
  double noise_px = 0.1;
  double hidden = 0.0;     // probability that a camera misses a marker
  double split = 0.0;      // probability of a second blob 0.5..3 px from a marker's
  double duplicate = 0.0;  // probability of an exact duplicate of a marker's blob
  // Probability that a view's centroid is shifted 2..6 px (a partly hidden ball: beyond
  // the gate, within the ball's image; an unfit view).
  double shifted = 0.0;
  // Probability of a second ball 14..20 mm from a marker (two balls close together);
  // where their images lie within 5 px they merge into one blob at the mean.
  double twin = 0.0;
  // Self-occlusion: each marker sits on the body's surface with a random outward normal
  // and is seen only by cameras within this angle of it (90: the half-space in front of
  // its tangent plane, a convex body's occlusion; 180: every camera).
  double facing_deg = 180.0;
};

// A property test's random ring: `cameras` cameras 2.5-3.5 m from the volume, each
// jittered by up to 15 degrees on the ring.
inline Rig random_ring_rig(int cameras, std::mt19937& rng) {
  RingOptions ro;
  ro.cameras = cameras;
  ro.radius_mm = 2500.0 + 1000.0 * std::uniform_real_distribution<double>(0.0, 1.0)(rng);
  ro.jitter_deg = 15.0;
  return humanoid_ring_rig(ro, rng);
}

// A property test's random scene: 5..max_markers markers, 0..max_strays strays per
// camera, each view missed with a probability up to max_hidden; the other options at
// their defaults (the test sets the corner cases it mixes in).
inline SceneOptions random_scene(int max_markers, int max_strays, double max_hidden,
                                 std::mt19937& rng) {
  SceneOptions so;
  so.markers = 5 + static_cast<int>(rng() % static_cast<unsigned>(max_markers - 4));
  so.strays = static_cast<int>(rng() % static_cast<unsigned>(max_strays + 1));
  so.hidden = max_hidden * std::uniform_real_distribution<double>(0.0, 1.0)(rng);
  return so;
}

// One frame: per camera, the blobs (shuffled). markers_world (optional) receives every
// marker's position, the second balls of twins included.
inline std::vector<std::vector<Vec2>> humanoid_frame(const Rig& rig, const SceneOptions& o,
                                                     std::mt19937& rng,
                                                     std::vector<Vec3>* markers_world = nullptr) {
  std::uniform_real_distribution<double> u(-1.0, 1.0), u01(0.0, 1.0);
  std::normal_distribution<double> noise(0.0, o.noise_px);
  std::vector<std::vector<Vec2>> px(rig.cameras.size());
  for (int i = 0; i < o.markers; ++i) {
    const Vec3 X(o.half_extent_mm.x() * u(rng), o.half_extent_mm.y() * u(rng),
                 o.half_extent_mm.z() * u(rng));
    Vec3 normal(u(rng), u(rng), u(rng));
    while (normal.squaredNorm() > 1.0 || normal.squaredNorm() < 1e-6)
      normal = Vec3(u(rng), u(rng), u(rng));
    normal.normalize();
    const double min_cos = std::cos(o.facing_deg * M_PI / 180.0);
    // Draws only for options in use: the scenes of the other options stay the same.
    const bool twin = o.twin > 0.0 && u01(rng) < o.twin;
    Vec3 X2 = X;
    if (twin) {
      Vec3 d(u(rng), u(rng), u(rng));
      while (d.squaredNorm() < 1e-6) d = Vec3(u(rng), u(rng), u(rng));
      X2 = X + (14.0 + 6.0 * u01(rng)) * d.normalized();
    }
    if (markers_world != nullptr) {
      markers_world->push_back(X);
      if (twin) markers_world->push_back(X2);
    }
    for (std::size_t c = 0; c < rig.cameras.size(); ++c) {
      Vec2 p;
      if (!project(rig.cameras[c], X, p) || !in_image(rig.cameras[c], p)) continue;
      if (twin) {
        Vec2 p2;
        if (project(rig.cameras[c], X2, p2) && in_image(rig.cameras[c], p2)) {
          if ((p2 - p).norm() < 5.0) {
            p = 0.5 * (p + p2);  // one merged blob
          } else {
            px[c].push_back(p2 + Vec2(noise(rng), noise(rng)));
          }
        }
      }
      if (o.shifted > 0.0 && u01(rng) < o.shifted) {
        const double r = 2.0 + 4.0 * u01(rng), t = M_PI * u(rng);
        p += r * Vec2(std::cos(t), std::sin(t));
      }
      if (normal.dot((rig.cameras[c].center_world() - X).normalized()) < min_cos) continue;
      if (u01(rng) < o.hidden) continue;
      const Vec2 b = p + Vec2(noise(rng), noise(rng));
      px[c].push_back(b);
      if (u01(rng) < o.split) {
        const double r = 0.5 + 2.5 * u01(rng), t = M_PI * u(rng);
        px[c].push_back(b + r * Vec2(std::cos(t), std::sin(t)));
      }
      if (u01(rng) < o.duplicate) px[c].push_back(b);
    }
  }
  for (std::size_t c = 0; c < px.size(); ++c) {
    const CameraModel& cam = rig.cameras[c];
    for (int s = 0; s < o.strays; ++s)
      px[c].push_back(Vec2(u01(rng) * (cam.width - 1.0), u01(rng) * (cam.height - 1.0)));
    std::shuffle(px[c].begin(), px[c].end(), rng);
  }
  return px;
}

}  // namespace mocap::test
