// Design: the library entry point of `mocap simulate`: builds the scene from
// SimOptions, plans the motion, renders every frame of every camera (2..32) and writes
// the recording folder (spec: rig.yaml, frames.csv, cam0/, cam1/, ...), targets.yaml,
// joints.yaml and the ground truth under gt/ (poses.csv, angles.csv, markers.csv,
// strays.csv, segments.csv, model_true.yaml); see docs/simulator.md for every file
// and column. Setup-style code: errors are one line, "simulate: key: problem" or
// "<path>: problem".
#pragma once

#include <cstdint>
#include <functional>
#include <string>

#include "core/expected.h"
#include "sim/motion.h"
#include "sim/scene.h"

namespace mocap::sim {

struct SimOptions {
  SceneKind scene = SceneKind::kLimbs;  // the robot and its layout (scene_layouts.h)
  std::string rig_path;  // user rig (rig.yaml, 2..32 cameras) instead of the built-in
  int cameras = 0;  // built-in cameras 2..8, humanoid 2..32 (0: the scene's default: the pair, 8)
                    // with rig_path: 0 or its count
  int frames = 100;
  MotionKind motion = MotionKind::kSmooth;
  std::uint64_t seed = 1;
  double noise_dn = -1.0;  // read noise sigma in output DN; < 0: default (1.5 DN at 8 bits, scaled)
  double blur_px = 0.5;    // Gaussian PSF sigma
  int stray = 0;           // number of glint spots
  bool streak = false;     // bright elongated reflection on the lower arm
  double dropout = 0.0;    // per marker, camera and frame
  int bits = 8;            // 8 or 16
  int maxval = 0;          // 0: 255 for 8 bits, 4095 for 16 bits
  double fps = 100.0;
  int poses = 22;
  int threads = 2;  // rendering threads (1 or 2)
};

struct SimSummary {
  int frames = 0;
  int cameras = 0;
  std::int64_t marker_views = 0;    // markers x cameras x frames
  std::int64_t isolated_views = 0;  // vis = 1 in gt/markers.csv
  std::int64_t occluded_views = 0;  // partly or fully hidden by a limb, stalk or ball
  std::int64_t dropped_views = 0;
  std::int64_t stray_blobs = 0;  // glints drawn (streak points not counted)
  double seconds = 0.0;
};

// The scene these options describe (imaging levels scaled to the bit depth).
Expected<SimScene> make_scene(const SimOptions& options);

// The motion these options describe (kind, frames, fps, poses, seed).
MotionSpec motion_spec(const SimOptions& options);

// The per-frame noise key of the renderer (seed and frame only).
std::uint64_t frame_noise_key(std::uint64_t seed, std::int64_t frame) noexcept;

// Writes the whole recording into dir (created if needed). progress(done_frames) is
// called after each frame when given.
Expected<SimSummary> write_simulated_recording(const SimOptions& options, const std::string& dir,
                                               const std::function<void(int)>& progress = {});

// Joint angles of one joint from the two body poses (the ground truth's definition):
// ball: (a0, a1, a2) with R_parent^T R_child = Rx(a0) Ry(a1) Rz(a2) (core/rotation.h);
// hinge: (angle, 0, 0), the signed rotation about axis_parent of
// R_rel * R_rel_zero^T, where R_rel_zero is the joint's extra "zero_q_parent_child".
Vec3 joint_angles_rad(const JointSpec& joint, const Iso3& T_world_parent,
                      const Iso3& T_world_child);

}  // namespace mocap::sim
