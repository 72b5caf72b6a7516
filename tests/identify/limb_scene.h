// Design: a humanoid-like moving scene for the temporal tests and the benchmarks. Each
// body is a limb: 4-6 markers on short bases (10-25 mm) all around a 30 mm limb, 180 mm
// long, swinging about its joint (peak ~460 deg/s) while the joint sways; the fastest
// markers move at ~2 m/s. The target's frame is put away from its markers (at the joint
// or, for every other body, ~0.6-1 m away, as a discovered or world-aligned target
// would be): the tracker must not depend on where a target's frame lies.
#pragma once

#include <cmath>
#include <random>
#include <string>
#include <vector>

#include "formats/targets_yaml.h"
#include "tests/identify/identify_test_util.h"

namespace mocap::test {

struct LimbMotion {
  Vec3 joint_mm = Vec3::Zero();
  Vec3 sway_dir = Vec3::UnitX();
  double sway_mm = 80.0, sway_hz = 1.0, sway_phase = 0.0;
  Vec3 axis = Vec3::UnitZ();
  double swing_rad = 1.0, swing_hz = 1.27, swing_phase = 0.0;
  Mat3 R0 = Mat3::Identity();
  Iso3 T_limb_body = Iso3::Identity();  // where the target's frame lies on the limb

  Iso3 T_world_body(double t_s) const {
    constexpr double kTwoPi = 6.283185307179586;
    const double sway = sway_mm * std::sin(kTwoPi * sway_hz * t_s + sway_phase);
    const double swing = swing_rad * std::sin(kTwoPi * swing_hz * t_s + swing_phase);
    Iso3 T = Iso3::Identity();
    T.linear() = Eigen::AngleAxisd(swing, axis).toRotationMatrix() * R0;
    T.translation() = joint_mm + sway * sway_dir;
    return T * T_limb_body;
  }
};

struct LimbScene {
  TargetSet set;
  std::vector<LimbMotion> limbs;
  std::vector<Iso3> poses(double t_s) const {
    std::vector<Iso3> p;
    for (const auto& l : limbs) p.push_back(l.T_world_body(t_s));
    return p;
  }
};

// k markers in the limb frame (x along the limb from the joint), >= 25 mm apart, pair
// distances of the target > 2 mm apart; returned in the target's frame.
inline MarkerTarget limb_target(std::mt19937_64& rng, int k, const std::string& name,
                                const Iso3& T_limb_body) {
  std::uniform_real_distribution<double> u(0.0, 1.0);
  for (;;) {
    std::vector<Vec3> X;
    std::vector<double> d;
    for (int tries = 0; tries < 4000 && static_cast<int>(X.size()) < k; ++tries) {
      const double phi = 6.283185307179586 * u(rng);
      const double r = 30.0 + 10.0 + 15.0 * u(rng);
      const Vec3 x(20.0 + 160.0 * u(rng), r * std::cos(phi), r * std::sin(phi));
      std::vector<double> nd;
      bool ok = true;
      for (const Vec3& q : X) {
        nd.push_back((q - x).norm());
        ok = ok && nd.back() >= 25.0;
      }
      for (std::size_t i = 0; ok && i < nd.size(); ++i) {
        for (double e : d) ok = ok && std::abs(nd[i] - e) > 2.0;
        for (std::size_t j = i + 1; ok && j < nd.size(); ++j) ok = std::abs(nd[i] - nd[j]) > 2.0;
      }
      if (!ok) continue;
      X.push_back(x);
      d.insert(d.end(), nd.begin(), nd.end());
    }
    if (static_cast<int>(X.size()) < k) continue;
    MarkerTarget t;
    t.name = name;
    for (const Vec3& x : X) t.markers_body.push_back(T_limb_body.inverse() * x);
    return t;
  }
}

// `bodies` limbs on a grid of joints spacing_mm apart, 2 m from the cameras.
inline LimbScene make_limb_scene(std::mt19937_64& rng, int bodies, double spacing_mm = 400.0) {
  std::uniform_real_distribution<double> u(0.0, 1.0);
  LimbScene s;
  for (int b = 0; b < bodies; ++b) {
    LimbMotion m;
    m.joint_mm =
        Vec3(spacing_mm * (b % 5), spacing_mm * ((b / 5) % 3), 2000.0 + spacing_mm * (b / 15));
    m.sway_dir = random_rotation(rng).col(0);
    m.sway_phase = 6.28 * u(rng);
    m.axis = random_rotation(rng).col(0);
    m.swing_phase = 6.28 * u(rng);
    m.R0 = random_rotation(rng);
    m.T_limb_body = Iso3::Identity();
    if (b % 2 == 1)  // a frame far from the markers
      m.T_limb_body.translation() = random_rotation(rng).col(0) * (600.0 + 400.0 * u(rng));
    s.set.bodies.push_back(limb_target(rng, 4 + b % 3, "limb" + std::to_string(b), m.T_limb_body));
    s.limbs.push_back(m);
  }
  return s;
}

// Fastest marker speed of the scene over [0, duration] (finite differences, mm/s).
inline double fastest_marker_mm_per_s(const LimbScene& s, double duration_s, double dt_s) {
  double v = 0.0;
  for (std::size_t b = 0; b < s.limbs.size(); ++b)
    for (double t = 0.0; t < duration_s; t += dt_s)
      for (const Vec3& M : s.set.bodies[b].markers_body)
        v = std::max(
            v,
            (s.limbs[b].T_world_body(t + 1e-4) * M - s.limbs[b].T_world_body(t) * M).norm() / 1e-4);
  return v;
}

}  // namespace mocap::test
