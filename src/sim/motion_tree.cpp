// Design: see motion_tree.h.
#include "sim/motion_tree.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>

#include "core/rotation.h"
#include "core/units.h"
#include "sim/sim_rng.h"

namespace mocap::sim {
namespace {

constexpr double kFullTurnRad = 2.0 * std::numbers::pi;
constexpr double kGolden = 0.6180339887498949;

double fractional_part(double x) { return x - std::floor(x); }

int dof_count(const SimJoint& j) { return j.type == JointType::kBall ? 3 : 1; }

// The root's sway and turn about the robot's centre at time t (smooth, explore).
Iso3 root_motion(const SimScene& scene, double t) {
  const Vec3 shift(50.0 * std::sin(kFullTurnRad * 0.21 * t + 0.4),
                   80.0 * std::sin(kFullTurnRad * 0.15 * t + 1.3),
                   20.0 * std::sin(kFullTurnRad * 0.43 * t + 2.2));
  const Mat3 R = rot_z(25.0 * kRadPerDeg * std::sin(kFullTurnRad * 0.11 * t + 0.7));
  const Vec3& c = scene.robot_center_world;
  return make_iso(R, c + shift - R * c);
}

// Every degree of freedom on its sinusoid: share of the half range, frequency per d.
template <typename Hz>
void plan_sinusoids(const SimScene& scene, const MotionSpec& spec, double share, Hz hz,
                    MotionPlan& plan) {
  for (int f = 0; f < spec.frames; ++f) {
    const double t = f / spec.fps;
    JointConfig c = make_config(scene);
    c.T_world_robot = root_motion(scene, t);
    int d = 0;
    for (std::size_t k = 0; k < scene.tree.size(); ++k) {
      const SimJoint& j = scene.tree[k];
      for (int i = 0; i < dof_count(j); ++i, ++d) {
        const double mid = 0.5 * (j.lower_rad[i] + j.upper_rad[i]);
        const double half = 0.5 * (j.upper_rad[i] - j.lower_rad[i]);
        const double phase = kFullTurnRad * fractional_part(0.37 + d * kGolden * 3.7);
        c.q_rad[k][i] = mid + share * half * std::sin(kFullTurnRad * hz(d) * t + phase);
      }
    }
    plan.configs.push_back(c);
  }
  plan.segments.push_back(MotionSegment{"move", 0, spec.frames - 1, Vec3::Zero()});
}

constexpr std::array<int, 48> kPrimes = {
    2,   3,   5,   7,   11,  13,  17,  19,  23,  29,  31,  37,  41,  43,  47,  53,
    59,  61,  67,  71,  73,  79,  83,  89,  97,  101, 103, 107, 109, 113, 127, 131,
    137, 139, 149, 151, 157, 163, 167, 173, 179, 181, 191, 193, 197, 199, 211, 223};

}  // namespace

double halton(int index, int base) noexcept {
  double f = 1.0, r = 0.0;
  for (int i = index; i > 0; i /= base) {
    f /= base;
    r += f * (i % base);
  }
  return r;
}

void hold_poses(const std::vector<JointConfig>& poses, int frames, MotionPlan& plan) {
  const auto n = static_cast<std::int64_t>(poses.size());
  for (int f = 0; f < frames; ++f) {
    plan.configs.push_back(
        poses[static_cast<std::size_t>(static_cast<std::int64_t>(f) * n / frames)]);
  }
  int first = 0;
  for (int f = 1; f <= frames; ++f) {
    const auto k_prev = static_cast<std::int64_t>(f - 1) * n / frames;
    const auto k_cur = static_cast<std::int64_t>(f) * n / frames;
    if (f == frames || k_cur != k_prev) {
      plan.segments.push_back(MotionSegment{"hold", first, f - 1, Vec3::Zero()});
      first = f;
    }
  }
}

JointConfig tree_fixed_pose(const SimScene& scene) {
  JointConfig c = make_config(scene);
  for (std::size_t k = 0; k < scene.tree.size(); ++k) {
    const SimJoint& j = scene.tree[k];
    c.q_rad[k] = j.lower_rad + 0.4 * (j.upper_rad - j.lower_rad);
  }
  return c;
}

void plan_tree_smooth(const SimScene& scene, const MotionSpec& spec, MotionPlan& plan) {
  plan_sinusoids(
      scene, spec, 0.8, [](int d) { return 0.25 + 0.5 * fractional_part(d * kGolden); }, plan);
}

void plan_tree_explore(const SimScene& scene, const MotionSpec& spec, MotionPlan& plan) {
  const double duration_s = spec.frames / spec.fps;
  plan_sinusoids(
      scene, spec, 0.95,
      [duration_s](int d) { return std::min(1.2, (1.0 + fractional_part(d * kGolden)) / duration_s); }, plan);
}

void plan_tree_poses(const SimScene& scene, const MotionSpec& spec, MotionPlan& plan) {
  std::vector<JointConfig> poses;
  Rng rng(hash_mix(spec.seed, 0x706F736573ull));
  for (int p = 0; p < spec.poses; ++p) {
    JointConfig c = make_config(scene);
    std::size_t d = 0;
    for (std::size_t k = 0; k < scene.tree.size(); ++k) {
      const SimJoint& j = scene.tree[k];
      for (int i = 0; i < dof_count(j); ++i, ++d) {
        // A Weyl sequence per degree of freedom (fractional_part(sqrt(prime))): well spread for
        // any number of poses, unlike Halton in large bases.
        const double u =
            fractional_part(0.5 + (p + 1) * std::sqrt(static_cast<double>(kPrimes[d % kPrimes.size()])));
        const double jitter = rng.uniform(-0.03, 0.03);
        c.q_rad[k][i] = j.lower_rad[i] + (0.05 + 0.9 * std::clamp(u + jitter, 0.0, 1.0)) *
                                             (j.upper_rad[i] - j.lower_rad[i]);
      }
    }
    poses.push_back(c);
  }
  hold_poses(poses, spec.frames, plan);
}

}  // namespace mocap::sim
