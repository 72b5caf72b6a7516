// Design: the pieces every built-in scene is assembled from (scene.cpp: the shoulder
// rig, scene_humanoid.cpp: the humanoid). A builder places its bodies, limbs, markers
// and joint centres in the world at the reference configuration and these helpers
// express them in the bodies' own frames (SimScene::T_world_body_ref), so body frames
// are never aligned with the world or with each other by construction. Setup code.
#pragma once

#include <string>

#include "core/expected.h"
#include "sim/scene.h"

namespace mocap::sim {

// Checks shared by every scene: the imaging parameters, the glint count and, without a
// user rig, the built-in camera count (2..8, the humanoid 2..32).
Expected<void> check_scene_options(const SceneOptions& options);

// A limb capsule of body b given in the world at the reference configuration.
void add_capsule(SimScene& scene, int body, const Vec3& a_world, const Vec3& b_world,
                 double radius_mm, bool shiny);

// A marker ball of body b centred at center_world, held by a dark post (radius
// post_radius_mm) from post_root_world (inside the limb) to the ball centre. Returns
// the marker's index within the body's target.
int add_marker(SimScene& scene, int body, const Vec3& center_world, const Vec3& post_root_world,
               double post_radius_mm);

// Joint `name` from parent to child at center_world (a hinge about axis_world); a ball
// joint is commanded in the axes R_parent_cmd (parent frame); the ranges bound the
// commanded angles of the motions. Appends to scene.tree and scene.joints_true.
void add_joint(SimScene& scene, const std::string& name, JointType type, int parent, int child,
               const Vec3& center_world, const Vec3& axis_world, const Mat3& R_parent_cmd,
               const Vec3& lower_rad, const Vec3& upper_rad);

// The frame that azimuths about a limb from a to b are measured in (world, reference
// pose): d along the limb, front = the side facing -Y (for a limb along Y: the top),
// side = +X for a vertical limb; azimuth phi points to sin(phi) side + cos(phi) front.
void limb_azimuth_frame(const Vec3& a, const Vec3& b, Vec3& d, Vec3& front, Vec3& side);

// Places options.stray_glints shiny spots on the bodies' main capsules (the first
// capsule of each body), from the seed.
void place_glints(const SceneOptions& options, SimScene& scene);

// Takes options.rig (checked against the scene) or the given built-in cameras (checked
// when check_built_in).
Expected<void> set_cameras(const SceneOptions& options, std::vector<CameraModel> built_in,
                           bool check_built_in, SimScene& scene);

}  // namespace mocap::sim
