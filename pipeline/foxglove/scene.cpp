// Design: see scene.h.
#include "pipeline/foxglove/scene.h"

#include <algorithm>
#include <cmath>

#include "core/camera_set.h"

namespace mocap::foxglove {

Rgba body_colour(int index, int count) noexcept {
  const int n = count > 0 ? count : 1;
  // Hue in [0, 1): HSV with S = 0.8, V = 0.95 to RGB.
  const double h = 6.0 * (static_cast<double>(index % n) / n);
  const double v = 0.95, s = 0.8;
  const double c = v * s;
  const double x = c * (1.0 - std::fabs(std::fmod(h, 2.0) - 1.0));
  const double m = v - c;
  double r = 0, g = 0, b = 0;
  switch (static_cast<int>(h)) {
    case 0:
      r = c, g = x;
      break;
    case 1:
      r = x, g = c;
      break;
    case 2:
      g = c, b = x;
      break;
    case 3:
      g = x, b = c;
      break;
    case 4:
      r = x, b = c;
      break;
    default:
      r = c, b = x;
      break;
  }
  return Rgba{r + m, g + m, b + m, 1.0};
}

Expected<FoxgloveScene> make_scene(const TargetSet& targets, const JointModel* model,
                                   const Rig* rig, const std::string& world_frame) {
  const std::string where = "foxglove";
  if (world_frame.empty()) return make_error(where, "world frame", "must not be empty");
  FoxgloveScene scene;
  scene.world_frame = world_frame;
  scene.marker_diameter_mm = targets.marker_diameter_mm;
  const int n = static_cast<int>(targets.bodies.size());
  for (int i = 0; i < n; ++i) {
    const std::string& name = targets.bodies[i].name;
    if (name.empty() || name == world_frame) {
      return make_error(where, "targets: body " + std::to_string(i),
                        "name '" + name + "' cannot be a frame id (empty or the world frame)");
    }
    scene.bodies.push_back(SceneBody{name, body_colour(i, n)});
  }
  if (rig != nullptr) {
    const std::size_t shown =  // every camera of the rig (2..kMaxCameras)
        std::min<std::size_t>(rig->cameras.size(), static_cast<std::size_t>(kMaxCameras));
    for (std::size_t c = 0; c < shown; ++c) {
      const CameraModel& cam = rig->cameras[c];
      const bool topic_ok = !cam.name.empty() && cam.name.size() <= 64 &&
                            cam.name.find_first_not_of(
                                "abcdefghijklmnopqrstuvwxyz"
                                "ABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789_-") == std::string::npos;
      if (!topic_ok) {
        return make_error(where, "rig: camera " + std::to_string(c),
                          "name '" + cam.name + "' is not a topic name (letters, digits, _ or -)");
      }
      if (cam.width <= 0 || cam.height <= 0 || cam.width > 16384 || cam.height > 16384)
        return make_error(where, "rig: camera " + cam.name, "image size out of range");
      scene.cameras.push_back(SceneCamera{cam.name, cam.width, cam.height});
    }
  }
  if (model == nullptr) return scene;
  for (const JointSpec& j : model->joints) {
    if (j.parent_index < 0 || j.parent_index >= n || j.child_index < 0 || j.child_index >= n) {
      return make_error(where, "joint '" + j.name + "'",
                        "parent or child is not a body of the targets");
    }
    SceneJoint sj;
    sj.name = j.name;
    sj.type = j.type;
    sj.parent = j.parent_index;
    sj.child = j.child_index;
    sj.calibrated = j.calibrated && j.center_parent.allFinite() && j.axis_parent.allFinite() &&
                    j.axis_parent.norm() > 0.0;
    sj.center_parent_mm = j.center_parent;
    if (sj.calibrated) sj.axis_parent = j.axis_parent.normalized();
    scene.joints.push_back(sj);
  }
  return scene;
}

}  // namespace mocap::foxglove
