// Design: the simulator's motions, as one JointConfig per frame (setup-time plans; a
// live simulated camera can also evaluate motion_config() frame by frame):
//  - smooth:     shoulder (3 DOF) and elbow follow sinusoids of different frequencies
//                over a wide, physically plausible range; the torso stays still.
//  - poses:      N distinct static poses (default 22, like the paper), quasi-random
//                (Halton) over the range of motion, each held for frames/N frames.
//  - move400:    fixed joint angles; the whole robot is moved rigidly over exactly
//                400 mm, four times in four directions, away from the cameras
//                (the paper's Table 1A).
//  - viewpoints: fixed joint angles; the whole robot is rotated (yaw up to +-55 deg,
//                pitch +-20, roll +-10) and translated rigidly relative to the cameras,
//                like moving the camera (the paper's Table 1B).
//  - explore:    every joint through (95 % of) its range at once, each degree of
//                freedom on a sinusoid of its own frequency (at least one cycle over the
//                recording), the root swaying: what `mocap discover` learns a robot from.
// The humanoid's smooth and poses plans are the generic ones of motion_tree.h.
// Segments tell which frame ranges are static holds (gt/segments.csv).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "core/expected.h"
#include "sim/scene.h"

namespace mocap::sim {

enum class MotionKind { kSmooth, kPoses, kMove400, kViewpoints, kExplore };

const char* motion_name(MotionKind kind) noexcept;
Expected<MotionKind> parse_motion(const std::string& name);

struct MotionSpec {
  MotionKind kind = MotionKind::kSmooth;
  int frames = 100;
  double fps = 100.0;
  int poses = 22;          // poses motion only
  std::uint64_t seed = 1;  // jitter of the poses
};

struct MotionSegment {
  std::string kind;  // "hold" (static) or "move"
  int first_frame = 0;
  int last_frame = 0;
  Vec3 robot_translation_mm = Vec3::Zero();  // T_world_robot's translation during a hold
};

struct MotionPlan {
  std::vector<JointConfig> configs;  // one per frame
  std::vector<MotionSegment> segments;
};

// Validates the spec ("simulate: frames: ..." errors) and plans every frame.
Expected<MotionPlan> plan_motion(const SimScene& scene, const MotionSpec& spec);

// Timestamp of a frame in nanoseconds at the spec's frame rate (frame 0 at 0 ns).
std::int64_t frame_timestamp_ns(std::int64_t frame, double fps) noexcept;

}  // namespace mocap::sim
