// Design: the JSON schemas this server advertises for its channels (schemaEncoding
// "jsonschema"), written here from Foxglove's published message definitions: they
// describe exactly the fields the encoders emit (types, units, required keys). The
// Foxglove app recognises /tf and /markers by schema name (foxglove.FrameTransforms,
// foxglove.SceneUpdate); the schema text gives it the field types for its panels.
#pragma once

#include <string>

namespace mocap::foxglove {

std::string frame_transforms_schema();  // foxglove.FrameTransforms
std::string scene_update_schema();      // foxglove.SceneUpdate
std::string joints_schema();            // mocap.JointAngles (this project's own)
std::string bodies_schema();            // mocap.BodyStates (this project's own)
std::string raw_image_schema();         // foxglove.RawImage

}  // namespace mocap::foxglove
