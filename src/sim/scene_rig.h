// Design: rendering the built-in scene through a user-given rig (`mocap simulate
// --rig rig.yaml`): other lenses (strong barrel or pincushion distortion, off-centre
// principal points, wide angle) and other camera placements than the ones the tracker
// was written against. The rig replaces the scene's cameras; the robot, its markers and
// the image physics stay the same. Before anything is rendered, the rig is checked
// against the scene, each problem one line naming the rig file and the camera (the
// built-in cameras for --cameras 3..8 go through the same check):
//  - 2 to 32 cameras (the spec's extension of 2026-12: 2 to 8; 2027-01: 32), with distinct names
//  that can be
//    recording folders (not empty, not 'gt', no '/');
//  - a physical lens over the whole image: every image corner undistorts, and the
//    radial mapping r -> r * (1 + k1 r^2 + k2 r^4 + k3 r^6) keeps increasing out to the
//    farthest corner (a lens whose model folds over inside the image would map two
//    directions onto one pixel, and the renderer would not be honest there);
//  - the scene in view: at the reference configuration (arm hanging down) every marker
//    is in front of the camera and its image lies inside the image, and its projection
//    inverts back onto its own ray (no fold at the marker).
// Setup-time code (allocates, returns Expected).
#pragma once

#include <string>

#include "camera/camera_model.h"
#include "core/expected.h"

namespace mocap::sim {

struct SimScene;

// Checks `rig` for rendering `scene` (its markers and reference configuration; its own
// rig is ignored). `source` names the rig in errors (the file path).
Expected<void> check_rig_for_scene(const Rig& rig, const SimScene& scene,
                                   const std::string& source);

}  // namespace mocap::sim
