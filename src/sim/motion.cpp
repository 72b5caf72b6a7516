// Design: closed-form motion plans (see motion.h). Angles in radians. The shoulder
// rig's plans (smooth, poses) are its own: the commanded shoulder angles are
// R_cmd = Rx(q0) Ry(q1) Rz(q2) in torso axes (q0 < 0 raises the arm towards the
// cameras, q1 < 0 lifts it sideways away from the torso, q2 turns it about its own
// axis); the elbow angle bends the forearm towards the cameras. Other scenes' smooth
// and poses plans, and every scene's explore, come from the joint ranges
// (motion_tree.h); move400 and viewpoints move any scene's fixed pose rigidly.
#include "sim/motion.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>

#include "core/rotation.h"
#include "core/units.h"
#include "sim/motion_tree.h"
#include "sim/sim_rng.h"

namespace mocap::sim {
namespace {

constexpr double kTwoPi = 2.0 * std::numbers::pi;

// Joint angles of the static motions (move400, viewpoints): a pose in which every target
// shows at least 3 unoccluded, unmerged markers to both cameras at the reference position
// (pose 0 of the `poses` motion), as the paper's accuracy experiment needs all three
// targets in view. (With the elbow at 60 deg two lower-arm markers overlap in camera 1.)
// Other scenes: tree_fixed_pose (motion_tree.h).
JointConfig fixed_pose(const SimScene& scene) {
  if (scene.kind == SceneKind::kHumanoid) return tree_fixed_pose(scene);
  JointConfig c = make_config(scene);
  c.q_rad[kShoulderJoint] = Vec3(-27.5, -38.0, -24.0) * kRadPerDeg;
  c.q_rad[kElbowJoint].x() = 23.0 * kRadPerDeg;
  return c;
}

void plan_smooth(const SimScene& scene, const MotionSpec& spec, MotionPlan& plan) {
  const double duration_s = spec.frames / spec.fps;
  // At least ~0.7..1.7 cycles over the recording, at most 1.5 Hz.
  const std::array<double, 4> cycles = {0.9, 1.3, 0.7, 1.7};
  const std::array<double, 4> base_hz = {0.11, 0.17, 0.13, 0.23};
  std::array<double, 4> hz{};
  for (std::size_t i = 0; i < 4; ++i)
    hz[i] = std::min(1.5, std::max(base_hz[i], cycles[i] / duration_s));
  for (int f = 0; f < spec.frames; ++f) {
    const double t = f / spec.fps;
    JointConfig c = make_config(scene);
    c.q_rad[kShoulderJoint] = Vec3(-25.0 + 40.0 * std::sin(kTwoPi * hz[0] * t + 0.3),
                                   -28.0 + 26.0 * std::sin(kTwoPi * hz[1] * t + 1.1),
                                   35.0 * std::sin(kTwoPi * hz[2] * t + 2.0)) *
                              kRadPerDeg;
    c.q_rad[kElbowJoint].x() = (60.0 + 50.0 * std::sin(kTwoPi * hz[3] * t - 0.5)) * kRadPerDeg;
    plan.configs.push_back(c);
  }
  plan.segments.push_back(MotionSegment{"move", 0, spec.frames - 1, Vec3::Zero()});
}

void plan_poses(const SimScene& scene, const MotionSpec& spec, MotionPlan& plan) {
  std::vector<JointConfig> poses;
  Rng rng(hash_mix(spec.seed, 0x706F736573ull));
  for (int k = 0; k < spec.poses; ++k) {
    JointConfig c = make_config(scene);
    const double j0 = rng.uniform(-3.0, 3.0), j1 = rng.uniform(-3.0, 3.0);
    const double j2 = rng.uniform(-3.0, 3.0), j3 = rng.uniform(-3.0, 3.0);
    c.q_rad[kShoulderJoint] =
        Vec3(-70.0 + 85.0 * halton(k + 1, 2) + j0, -58.0 + 60.0 * halton(k + 1, 3) + j1,
             -40.0 + 80.0 * halton(k + 1, 5) + j2) *
        kRadPerDeg;
    c.q_rad[kElbowJoint].x() = (8.0 + 105.0 * halton(k + 1, 7) + j3) * kRadPerDeg;
    poses.push_back(c);
  }
  hold_poses(poses, spec.frames, plan);
}

void plan_move400(const SimScene& scene, const MotionSpec& spec, MotionPlan& plan) {
  const std::array<Vec3, 4> dirs = {Vec3(0.0, 1.0, 0.0), Vec3(0.4, 0.917, 0.0),
                                    Vec3(-0.4, 0.917, 0.0), Vec3(0.3, 0.8, 0.35)};
  const int n_moves = static_cast<int>(dirs.size());
  for (int m = 0; m < n_moves; ++m) {
    const int first = spec.frames * m / n_moves;
    const int last = spec.frames * (m + 1) / n_moves - 1;
    const int n = last - first + 1;
    const int hold = std::max(1, n / 4);
    const Vec3 d = dirs[static_cast<std::size_t>(m)].normalized();
    // From 150 mm nearer to 250 mm farther than the reference: 400 mm, all in view.
    const Vec3 start = -150.0 * d, end = 250.0 * d;
    const int move_first = first + hold, move_last = last - hold;  // frames strictly moving
    for (int f = first; f <= last; ++f) {
      double x = 0.0;
      if (f >= move_last + 1) {
        x = 1.0;
      } else if (f >= move_first) {
        x = (f - move_first + 1.0) / (move_last - move_first + 2.0);
      }
      const double s = x * x * (3.0 - 2.0 * x);
      JointConfig c = fixed_pose(scene);
      c.T_world_robot = make_iso(Mat3::Identity(), start + s * (end - start));
      plan.configs.push_back(c);
    }
    plan.segments.push_back(MotionSegment{"hold", first, move_first - 1, start});
    if (move_last >= move_first)
      plan.segments.push_back(MotionSegment{"move", move_first, move_last, Vec3::Zero()});
    plan.segments.push_back(MotionSegment{"hold", move_last + 1, last, end});
  }
}

void plan_viewpoints(const SimScene& scene, const MotionSpec& spec, MotionPlan& plan) {
  const Vec3 c = scene.robot_center_world;
  for (int f = 0; f < spec.frames; ++f) {
    const double x = spec.frames > 1 ? static_cast<double>(f) / (spec.frames - 1) : 0.0;
    const double yaw = 55.0 * std::sin(kTwoPi * 1.0 * x) * kRadPerDeg;
    const double pitch = 20.0 * std::sin(kTwoPi * 0.7 * x + 0.8) * kRadPerDeg;
    const double roll = 10.0 * std::sin(kTwoPi * 1.3 * x + 2.1) * kRadPerDeg;
    const Vec3 shift(60.0 * std::sin(kTwoPi * 0.5 * x), 120.0 * std::sin(kTwoPi * 0.9 * x + 1.0),
                     40.0 * std::sin(kTwoPi * 1.1 * x));
    const Mat3 R = rot_z(yaw) * rot_x(pitch) * rot_y(roll);
    JointConfig cfg = fixed_pose(scene);
    cfg.T_world_robot = make_iso(R, c + shift - R * c);
    plan.configs.push_back(cfg);
  }
  plan.segments.push_back(MotionSegment{"move", 0, spec.frames - 1, Vec3::Zero()});
}

}  // namespace

const char* motion_name(MotionKind kind) noexcept {
  switch (kind) {
    case MotionKind::kSmooth:
      return "smooth";
    case MotionKind::kPoses:
      return "poses";
    case MotionKind::kMove400:
      return "move400";
    case MotionKind::kViewpoints:
      return "viewpoints";
    case MotionKind::kExplore:
      return "explore";
  }
  return "smooth";
}

Expected<MotionKind> parse_motion(const std::string& name) {
  for (MotionKind k : {MotionKind::kSmooth, MotionKind::kPoses, MotionKind::kMove400,
                       MotionKind::kViewpoints, MotionKind::kExplore}) {
    if (name == motion_name(k)) return k;
  }
  return make_error("simulate", "motion",
                    "unknown motion '" + name + "' (smooth|poses|move400|viewpoints|explore)");
}

Expected<MotionPlan> plan_motion(const SimScene& scene, const MotionSpec& spec) {
  if (spec.frames < 1 || spec.frames > 1000000)
    return make_error("simulate", "frames", "must be 1..1000000");
  if (!(spec.fps > 0.0 && spec.fps <= 100000.0))
    return make_error("simulate", "fps", "must be in (0, 100000]");
  MotionPlan plan;
  plan.configs.reserve(static_cast<std::size_t>(spec.frames));
  const bool shoulder = scene.kind != SceneKind::kHumanoid;
  switch (spec.kind) {
    case MotionKind::kSmooth:
      if (shoulder) {
        plan_smooth(scene, spec, plan);
      } else {
        plan_tree_smooth(scene, spec, plan);
      }
      break;
    case MotionKind::kExplore:
      plan_tree_explore(scene, spec, plan);
      break;
    case MotionKind::kPoses:
      if (spec.poses < 1) return make_error("simulate", "poses", "must be >= 1");
      if (spec.frames < spec.poses)
        return make_error(
            "simulate", "frames",
            "must be at least the number of poses (" + std::to_string(spec.poses) + ")");
      if (shoulder) {
        plan_poses(scene, spec, plan);
      } else {
        plan_tree_poses(scene, spec, plan);
      }
      break;
    case MotionKind::kMove400:
      if (spec.frames < 12)
        return make_error("simulate", "frames", "move400 needs at least 12 frames");
      plan_move400(scene, spec, plan);
      break;
    case MotionKind::kViewpoints:
      plan_viewpoints(scene, spec, plan);
      break;
  }
  return plan;
}

std::int64_t frame_timestamp_ns(std::int64_t frame, double fps) noexcept {
  return static_cast<std::int64_t>(std::llround(static_cast<double>(frame) * 1e9 / fps));
}

}  // namespace mocap::sim
