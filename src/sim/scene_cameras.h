// Design: the built-in cameras of the simulator's shoulder rig, 2 to 8 (`mocap simulate
// --cameras N`; the humanoid's ring of up to 32 is in scene_humanoid.h).
//  - N = 2: the verged stereo pair of the scene (scene_layouts.h, CameraMount), exactly
//    as it always was (rig.yaml byte for byte).
//  - N = 3..8: the cameras stand on an arc around the robot, as a lab rigs a capture
//    volume around a robot whose torso carries its markers on the front and whose arm
//    hangs on the +X side: azimuths (about the vertical through
//    SimScene::robot_center_world, 0 = in front of the robot (-Y), + towards +X, the
//    arm's side) spread evenly from -60 deg (front left) to +150 deg (behind the arm),
//    1500 mm from the vertical through the robot centre, alternately 900 mm and 450 mm
//    above the robot centre, each aimed at the robot centre. So the cameras see the
//    robot from clearly different directions: from the front and the left the torso
//    hides part of the arm, from the right the arm passes in front of the torso, from
//    behind the torso's front balls are out of sight. Lenses: the pair's 6 mm optics
//    (1032 x 776 px) with the small unit-to-unit differences of real lenses (focal
//    length within 0.3 %, principal point within 5 px, k1 -0.116..-0.124) and a small
//    mounting roll, one fixed set per camera slot (kRingLenses).
// Every built-in placement for N >= 3 passes check_rig_for_scene (scene_rig.h) at the
// reference configuration (build_shoulder_scene checks it); over the motions a ball
// may leave one camera's image at times, as in a real lab.
// Setup-time code (allocates).
#pragma once

#include <vector>

#include "camera/camera_model.h"
#include "core/camera_set.h"
#include "core/types.h"
#include "sim/scene_layouts.h"

namespace mocap::sim {

inline constexpr int kMinSimCameras = 2;
// The limbs/stalks scenes' built-in cameras: the pair or an arc of up to 8.
inline constexpr int kMaxArcCameras = 8;
// Cameras the simulator renders: the humanoid's ring and a user rig, up to the rig bound.
inline constexpr int kMaxSimCameras = kMaxCameras;

// Where camera k of n (n >= 3) stands, relative to the robot centre.
struct RingSlot {
  double azimuth_deg = 0.0;  // about +Z, 0 = -Y (in front of the robot), + towards +X
  double distance_mm = 0.0;  // horizontal distance from the vertical through the centre
  double height_mm = 0.0;    // above the robot centre
};

RingSlot ring_slot(int k, int n) noexcept;

// The built-in cameras cam0..cam<n-1> for n in 2..kMaxArcCameras (n outside: empty).
// robot_center_world is where the ring cameras stand around and aim at (unused for n = 2).
std::vector<CameraModel> built_in_cameras(SceneKind kind, const Vec3& robot_center_world, int n);

}  // namespace mocap::sim
