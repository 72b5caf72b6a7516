// Design: the variants of the built-in scenes. Both scenes are the same robot (same
// limbs, joints, lenses and image physics); they differ in how the 12 mm balls and the
// two cameras are mounted:
//  - limbs  (default): what a robot lab builds, like the paper's targets. The arms carry
//           6 and 5 balls spread along each limb and around it, each on a short base
//           (3..5 mm between the limb surface and the ball): several face the cameras
//           over the motions, some sit on the far sides and the back. A ball seen more
//           than about 75 deg off its own axis loses a sliver of its rim to its base, and
//           the limb hides it from about 110 deg on; no ball sits on the side of the arm
//           facing the torso, where the arm would hit it. The torso stands still in front
//           of the cameras, so its 5 balls are spread over its front (within 65 deg of
//           the cameras), where the arm passing in front cannot hide 3 of them at once.
//           The cameras are mounted as a lab mounts them: centred on the robot, 0.9 m up
//           and 1.1 m in front, looking down at it (about 40 deg), so that a forearm
//           bent towards them still shows its upper side and the arm raised in front of
//           the torso does not hide the torso from either camera.
//  - stalks (stress variant): the original scene, 5, 5 and 4 balls on 10..25 mm stalks
//           on the side facing the cameras (azimuth -80..+70 deg), and the cameras at
//           the robot's height, 1 m in front, so that a few limb occlusions remove most
//           of a target and a forearm bent towards the cameras is seen end-on.
// A mount is given on the body's main limb at the reference configuration (arm hanging
// down): height on the limb axis, azimuth around it and the gap between the limb
// surface and the ball; the post that holds the ball is a dark capsule from inside the
// limb to the ball centre (it occludes like any limb). Layout numbers were chosen so that
// within a target all inter-marker distances differ by > 3 mm and no triangle of any
// target matches another triangle (of the same or another target) within 7 mm: the
// identifier's ambiguity check finds nothing at t = 5 mm (limbs: also 6 mm; tests/sim).
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "core/expected.h"

namespace mocap::sim {

// kHumanoid is the whole-body robot of scene_humanoid.h (its layout is its own).
enum class SceneKind : std::uint8_t { kLimbs, kStalks, kHumanoid };

const char* scene_name(SceneKind kind) noexcept;
// "limbs" | "stalks" | "humanoid"; error "simulate: scene: unknown scene 'x' (...)".
Expected<SceneKind> parse_scene(const std::string& name);

struct MarkerMount {
  double z_mm;     // height on the limb axis (world, reference configuration)
  double phi_deg;  // azimuth around the axis: 0 faces the cameras (-Y), + towards +X
  double gap_mm;   // limb surface to ball surface (the stalk or base length)
};

struct MarkerLayout {
  std::array<std::vector<MarkerMount>, 3> mounts;  // torso, upper_arm, lower_arm
  double post_radius_mm = 2.0;                     // radius of the stalk or base
};

const MarkerLayout& marker_layout(SceneKind kind);

// Where the two cameras stand (world, mm): at x = x_mm -+ 238.5 (a 477 mm baseline),
// y = y_mm and z = z_mm, both aimed at the point (x_mm, 250, aim_z_mm).
struct CameraMount {
  double x_mm = 0.0;
  double y_mm = -1000.0;
  double z_mm = 30.0;
  double aim_z_mm = 0.0;
};

CameraMount camera_mount(SceneKind kind) noexcept;

}  // namespace mocap::sim
