// Design: see schemas.h. Built from small nlohmann-json blocks (time, vector, quaternion,
// colour, pose) so that each message schema reads like its definition.
#include "pipeline/foxglove/schemas.h"

#include <nlohmann/json.hpp>

namespace mocap::foxglove {

using nlohmann::json;

namespace {

json object_of(json properties, const char* title = nullptr) {
  json required = json::array();
  for (const auto& item : properties.items()) required.push_back(item.key());
  json j = {{"type", "object"}, {"properties", std::move(properties)}, {"required", required}};
  if (title != nullptr) j["title"] = title;
  return j;
}
json number() { return {{"type", "number"}}; }
json integer() { return {{"type", "integer"}}; }
json string() { return {{"type", "string"}}; }
json boolean() { return {{"type", "boolean"}}; }
json array_of(json items) { return {{"type", "array"}, {"items", std::move(items)}}; }
json nullable(json schema) { return {{"anyOf", {std::move(schema), {{"type", "null"}}}}}; }

json time_schema() {
  return object_of({{"sec", {{"type", "integer"}, {"minimum", 0}}},
                    {"nsec", {{"type", "integer"}, {"minimum", 0}, {"maximum", 999999999}}}});
}
json vector3() {
  return object_of({{"x", number()}, {"y", number()}, {"z", number()}}, "foxglove.Vector3");
}
json quaternion() {
  return object_of({{"x", number()}, {"y", number()}, {"z", number()}, {"w", number()}},
                   "foxglove.Quaternion");
}
json colour() {
  return object_of({{"r", number()}, {"g", number()}, {"b", number()}, {"a", number()}},
                   "foxglove.Color");
}
json pose() {
  return object_of({{"position", vector3()}, {"orientation", quaternion()}}, "foxglove.Pose");
}

json sphere() {
  return object_of({{"pose", pose()}, {"size", vector3()}, {"color", colour()}},
                   "foxglove.SpherePrimitive");
}
json arrow() {
  return object_of({{"pose", pose()},
                    {"shaft_length", number()},
                    {"shaft_diameter", number()},
                    {"head_length", number()},
                    {"head_diameter", number()},
                    {"color", colour()}},
                   "foxglove.ArrowPrimitive");
}
json text() {
  return object_of({{"pose", pose()},
                    {"billboard", boolean()},
                    {"font_size", number()},
                    {"scale_invariant", boolean()},
                    {"color", colour()},
                    {"text", string()}},
                   "foxglove.TextPrimitive");
}

}  // namespace

std::string frame_transforms_schema() {
  json transform = object_of({{"timestamp", time_schema()},
                              {"parent_frame_id", string()},
                              {"child_frame_id", string()},
                              {"translation", vector3()},
                              {"rotation", quaternion()}},
                             "foxglove.FrameTransform");
  return object_of({{"transforms", array_of(transform)}}, "foxglove.FrameTransforms").dump();
}

std::string scene_update_schema() {
  const json unused = array_of(json::object());  // primitive kinds this server never sends
  json entity =
      object_of({{"timestamp", time_schema()},
                 {"frame_id", string()},
                 {"id", string()},
                 {"lifetime", time_schema()},
                 {"frame_locked", boolean()},
                 {"metadata", array_of(object_of({{"key", string()}, {"value", string()}}))},
                 {"arrows", array_of(arrow())},
                 {"cubes", unused},
                 {"spheres", array_of(sphere())},
                 {"cylinders", unused},
                 {"lines", unused},
                 {"triangles", unused},
                 {"texts", array_of(text())},
                 {"models", unused}},
                "foxglove.SceneEntity");
  json deletion = object_of({{"timestamp", time_schema()}, {"type", integer()}, {"id", string()}},
                            "foxglove.SceneEntityDeletion");
  return object_of({{"deletions", array_of(deletion)}, {"entities", array_of(entity)}},
                   "foxglove.SceneUpdate")
      .dump();
}

std::string joints_schema() {
  json joint = object_of({{"name", string()},
                          {"type", {{"type", "string"}, {"enum", {"ball", "hinge"}}}},
                          {"valid", boolean()},
                          {"angles_rad", array_of(number())},
                          {"solved_by", {{"type", "string"}, {"enum", {"none", "poses", "chain"}}}},
                          {"sd_rad", array_of(number())},
                          {"rate_rad_s", nullable(array_of(number()))},
                          {"rate_sd_rad_s", nullable(array_of(number()))}},
                         "mocap.JointAngle");
  return object_of({{"timestamp", time_schema()},
                    {"sequence", integer()},
                    {"all_bodies_found", boolean()},
                    {"joints", array_of(joint)}},
                   "mocap.JointAngles")
      .dump();
}

std::string bodies_schema() {
  const json vec3 = array_of(number());
  json body = {{"type", "object"},
               {"title", "mocap.BodyState"},
               {"properties",
                {{"name", string()},
                 {"found", boolean()},
                 {"markers", integer()},
                 {"rms_mm", number()},
                 {"position", vector3()},
                 {"orientation", quaternion()},
                 {"velocity_m_s", nullable(vec3)},
                 {"angular_velocity_rad_s", nullable(vec3)}}},
               {"required", {"name", "found"}}};
  return object_of({{"timestamp", time_schema()},
                    {"sequence", integer()},
                    {"frame_id", string()},
                    {"bodies", array_of(body)}},
                   "mocap.BodyStates")
      .dump();
}

std::string raw_image_schema() {
  // Foxglove's JSON encoding carries a bytes field as a base64 string.
  const json bytes = {{"type", "string"}, {"contentEncoding", "base64"}};
  const json uint32 = {{"type", "integer"}, {"minimum", 0}};
  return object_of({{"timestamp", time_schema()},
                    {"frame_id", string()},
                    {"width", uint32},
                    {"height", uint32},
                    {"encoding", string()},
                    {"step", uint32},
                    {"data", bytes}},
                   "foxglove.RawImage")
      .dump();
}

}  // namespace mocap::foxglove
