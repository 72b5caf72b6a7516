// Design: the immutable model of the Foxglove live view, built once at setup from the
// targets, the joint model and the rig (OutputContext): body names and colours, the
// world frame id, each calibrated joint's centre and hinge axis in its parent body's
// frame, and the rig cameras' names and image sizes (the blob overlays). The
// encoders (encode.h) read it, never change it. Units: the model keeps the project's
// millimetres; the encoders convert to Foxglove's metres.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "camera/camera_model.h"
#include "core/expected.h"
#include "core/types.h"
#include "formats/joints_yaml.h"
#include "formats/targets_yaml.h"

namespace mocap::foxglove {

struct Rgba {
  double r = 1.0, g = 1.0, b = 1.0, a = 1.0;  // 0..1
};

struct SceneBody {
  std::string name;  // child_frame_id of its transform
  Rgba colour;
};

struct SceneJoint {
  std::string name;
  JointType type = JointType::kBall;
  int parent = -1;  // body indices
  int child = -1;
  bool calibrated = false;
  Vec3 center_parent_mm = Vec3::Zero();
  Vec3 axis_parent = Vec3::UnitZ();  // hinge only, unit length
};

struct SceneCamera {
  std::string name;  // topic /<name>/blobs
  int width_px = 0;
  int height_px = 0;
};

struct FoxgloveScene {
  std::string world_frame = "mocap";  // parent_frame_id of every body transform
  double marker_diameter_mm = 12.0;
  std::vector<SceneBody> bodies;
  std::vector<SceneJoint> joints;    // empty without a joint model
  std::vector<SceneCamera> cameras;  // every rig camera (2..32); empty without a rig
};

// The colour of body i of n: evenly spaced, saturated hues (deterministic).
Rgba body_colour(int index, int count) noexcept;

// Fails with one line when a body name is empty or equals the world frame, the model
// names a body index outside the targets, or a camera name is not a topic segment.
// `rig` may be null (no blob overlays); each of its cameras gets a blob channel.
Expected<FoxgloveScene> make_scene(const TargetSet& targets, const JointModel* model,
                                   const Rig* rig = nullptr,
                                   const std::string& world_frame = "mocap");

}  // namespace mocap::foxglove
