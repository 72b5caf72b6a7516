// Design: the marker layouts of the built-in scenes. Both scenes are the same robot
// (same limbs, joints, cameras and image physics); only how the 12 mm balls are mounted
// differs:
//  - limbs  (default): what a robot lab builds, like the paper's targets: 6, 6 and 5
//           balls spread along each limb and around it, each on a short base (3..5 mm
//           between the limb surface and the ball). Four balls of each limb lie within
//           70 deg of the side facing the cameras, the others on the far sides and the
//           back: several are cleanly visible from the cameras over the motions and the
//           viewpoints, some are always behind the limb. A ball seen more than about
//           75 deg off its own axis loses a sliver of its rim to its base, and the limb
//           hides it from about 110 deg on; no ball sits on the side of the arm facing
//           the torso, where the arm would hit it.
//  - stalks (stress variant): the original scene, 5, 5 and 4 balls on 10..25 mm stalks
//           on the side facing the cameras (azimuth -80..+70 deg), so that a few
//           limb occlusions remove most of a target.
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

enum class SceneKind : std::uint8_t { kLimbs, kStalks };

const char* scene_name(SceneKind kind) noexcept;
// "limbs" | "stalks"; error "simulate: scene: unknown scene 'x' (limbs|stalks)".
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

}  // namespace mocap::sim
