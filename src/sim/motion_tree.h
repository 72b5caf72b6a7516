// Design: motions of any scene from its kinematic tree's joint ranges (SimJoint::
// lower_rad / upper_rad): the humanoid's smooth and poses plans, every scene's explore,
// and the fixed pose of the rigid motions. Each degree of freedom d (ball joints 3,
// hinges 1, in tree order) is driven on its own:
//  - smooth:  q = mid + 0.8 half-range sin(2 pi f_d t + p_d), f_d spread over
//             0.25..0.75 Hz (so a hand reaches about 2 m/s at its fastest, a fast but
//             normal arm motion); the root sways (+-50 mm, +-80 mm, +-20 mm) and turns
//             (+-25 deg yaw) about the robot's centre;
//  - explore: the same with 0.95 half-range and f_d = (1 + u_d) / duration (at least one
//             cycle of every degree of freedom over the recording, at most 1.2 Hz);
//  - poses:   N quasi-random (a Weyl sequence frac(k sqrt(p_d)), one prime per degree of
//             freedom) static poses over 90 % of the ranges, each held frames/N frames.
// Frequencies and phases are fixed numbers of d (golden-ratio spread): the motion does
// not depend on --seed; poses add the seed's jitter as the shoulder rig's do.
#pragma once

#include <vector>

#include "sim/motion.h"
#include "sim/scene.h"

namespace mocap::sim {

double halton(int index, int base) noexcept;

// Holds pose k for frames [k frames / n, (k + 1) frames / n) and records the holds.
void hold_poses(const std::vector<JointConfig>& poses, int frames, MotionPlan& plan);

JointConfig tree_fixed_pose(const SimScene& scene);
void plan_tree_smooth(const SimScene& scene, const MotionSpec& spec, MotionPlan& plan);
void plan_tree_explore(const SimScene& scene, const MotionSpec& spec, MotionPlan& plan);
void plan_tree_poses(const SimScene& scene, const MotionSpec& spec, MotionPlan& plan);

}  // namespace mocap::sim
