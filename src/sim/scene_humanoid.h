// Design: the simulator's whole-body humanoid (`mocap simulate --scene humanoid`,
// `sim: {scene: humanoid}`), the robot a lab instruments when it tracks the whole
// robot. 15 bodies (pelvis, torso, head, and per side upper arm, forearm, hand, thigh,
// shank, foot) and 14 joints (ball: waist, neck, shoulders, wrists, hips; hinge:
// elbows, knees, ankles), about 1.6 m tall, standing on the floor (z = 0) and facing
// -Y. Every limb is a set of capsules; 71 balls of 14 mm sit on 3..5 mm bases all
// around each limb (4 to 6 per body; none on the side of an arm or leg that faces the
// body, where the limbs would hit them). The layout comes from a seeded search with a
// fixed seed (the robot does not change with --seed) under the rules a lab designs
// targets by: balls at least 40 mm apart, the inter-marker distances of a target all
// differ by >= 4 mm, no triangle of a target fits another of the same target (or itself
// turned over) within 5.5 mm RMS after the best rigid motion (no symmetric target: the
// identifier warns below t = 5 mm), and none fits a triangle
// of another target within 2.5 mm (no copies; left and right are not mirror images).
// Triangles of different limbs may still fit within the identifier's t, as on a real
// robot: the tracker resolves those by continuity and the other markers.
// Cameras: a ring of N = 2..32 (default 8) 1280 x 1024 cameras around the robot, 3 m
// from the vertical through it, alternately 2.3 m and 1.5 m above the floor, every one
// aimed at the robot's centre; N = 2 is a pair in front of it. Motions (motion.h):
// smooth (every joint and the root), poses (static calibration poses) and explore
// (every joint through its range, for `mocap discover`).
// Body frames are placed with small deliberate rotations (never aligned with the world
// or with each other). Ball joints are commanded in world-aligned axes at the reference
// pose (X the robot's left, Y backwards, Z up). Setup code (allocates).
#pragma once

#include <vector>

#include "camera/camera_model.h"
#include "core/expected.h"
#include "sim/scene.h"

namespace mocap::sim {

inline constexpr int kHumanoidBodies = 15;
inline constexpr int kHumanoidJoints = 14;
inline constexpr int kHumanoidDefaultCameras = 8;

Expected<SimScene> build_humanoid_scene(const SceneOptions& options);

// The built-in ring of n (2..32) cameras around a robot centred at center_world (n
// outside: empty).
std::vector<CameraModel> humanoid_cameras(const Vec3& center_world, int n);

}  // namespace mocap::sim
