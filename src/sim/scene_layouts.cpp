// Design: see scene_layouts.h. The numbers of both layouts; docs/simulator.md has the
// table and a drawing. The limbs layout was found by a seeded search over azimuths,
// heights and gaps (constraints: azimuths cover the limb with no gap over 105 deg,
// heights at least 20 mm apart, no ball on the side facing the torso where the arm
// would hit it) maximising the distinctness of distances and triangles.
#include "sim/scene_layouts.h"

namespace mocap::sim {

const char* scene_name(SceneKind kind) noexcept {
  return kind == SceneKind::kStalks ? "stalks" : "limbs";
}

Expected<SceneKind> parse_scene(const std::string& name) {
  for (SceneKind k : {SceneKind::kLimbs, SceneKind::kStalks}) {
    if (name == scene_name(k)) return k;
  }
  return make_error("simulate", "scene", "unknown scene '" + name + "' (limbs|stalks)");
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
  // A lab's layout: balls all around each limb on 3 mm-radius bases of 3..5 mm.
  static const MarkerLayout limbs{{{
                                      {{101.9, -5.0, 3.0},
                                       {58.2, 6.1, 5.0},
                                       {23.7, -121.2, 4.0},
                                       {-18.0, -76.3, 3.0},
                                       {-49.6, -179.2, 4.0},
                                       {-92.2, 108.8, 4.0}},
                                      {{122.0, 116.3, 4.0},
                                       {93.4, 85.8, 3.0},
                                       {66.5, 3.4, 3.0},
                                       {33.9, -121.8, 4.0},
                                       {7.2, -57.2, 5.0},
                                       {-22.0, -170.4, 5.0}},
                                      {{-87.8, -121.2, 5.0},
                                       {-113.8, -8.8, 4.0},
                                       {-152.7, 173.0, 3.0},
                                       {-191.9, 87.2, 5.0},
                                       {-220.0, -34.3, 5.0}},
                                  }},
                                  3.0};
  return kind == SceneKind::kStalks ? stalks : limbs;
}

}  // namespace mocap::sim
