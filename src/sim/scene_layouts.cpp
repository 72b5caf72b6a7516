// Design: see scene_layouts.h. The numbers of both layouts; docs/simulator.md has the
// table and a drawing. The limbs layout was found by a seeded search over heights, gaps
// and azimuths (torso within +-8 deg of -45, -20, 5, 30, 55; upper arm within
// +-10 deg of -55, -20, 15, 50, 85, 150; lower arm within +-10 deg of -45, -5, 35, 75,
// 160; heights at least 20 mm apart) maximising the distinctness of inter-marker
// distances and triangles.
#include "sim/scene_layouts.h"

namespace mocap::sim {

const char* scene_name(SceneKind kind) noexcept {
  switch (kind) {
    case SceneKind::kStalks:
      return "stalks";
    case SceneKind::kHumanoid:
      return "humanoid";
    case SceneKind::kLimbs:
      break;
  }
  return "limbs";
}

Expected<SceneKind> parse_scene(const std::string& name) {
  for (SceneKind k : {SceneKind::kLimbs, SceneKind::kStalks, SceneKind::kHumanoid}) {
    if (name == scene_name(k)) return k;
  }
  return make_error("simulate", "scene", "unknown scene '" + name + "' (limbs|stalks|humanoid)");
}

const MarkerLayout& marker_layout(SceneKind kind) {
  // The original scene: balls on 2 mm-radius stalks of 10..25 mm, on the camera side.
  static const MarkerLayout stalks{
      {{
          {{150.0, -20.0, 12.0},
           {95.0, 35.0, 18.0},
           {10.0, -50.0, 10.0},
           {-60.0, 15.0, 25.0},
           {-110.0, -35.0, 15.0}},
          {{115.0, -30.0, 20.0},
           {78.0, 60.0, 19.0},
           {46.0, 0.0, 17.0},
           {2.0, -80.0, 17.0},
           {-26.0, 40.0, 12.0}},
          {{-87.0, 20.0, 15.0}, {-120.0, -45.0, 21.0}, {-175.0, 70.0, 21.0}, {-203.0, -5.0, 18.0}},
      }},
      2.0};
  // A lab's layout: balls along and around each limb on 2 mm-radius bases of 3..5 mm.
  static const MarkerLayout limbs{{{
                                      {{105.0, 5.6, 4.0},
                                       {60.0, 61.9, 4.0},
                                       {-45.0, 31.6, 5.0},
                                       {-57.0, -25.7, 4.0},
                                       {-106.0, -37.3, 3.0}},
                                      {{122.0, -45.0, 4.0},
                                       {93.9, 20.3, 3.0},
                                       {73.4, 140.0, 3.0},
                                       {37.2, 77.7, 5.0},
                                       {9.2, 41.5, 4.0},
                                       {-11.8, -17.6, 3.0}},
                                      {{-78.0, 65.0, 5.0},
                                       {-117.5, 157.1, 4.0},
                                       {-149.7, -37.6, 3.0},
                                       {-193.6, 36.3, 5.0},
                                       {-220.0, -12.0, 4.0}},
                                  }},
                                  2.0};
  return kind == SceneKind::kStalks ? stalks : limbs;
}

CameraMount camera_mount(SceneKind kind) noexcept {
  if (kind == SceneKind::kStalks) return CameraMount{0.0, -1000.0, 30.0, 0.0};
  return CameraMount{-150.0, -1100.0, 900.0, -200.0};
}

}  // namespace mocap::sim
