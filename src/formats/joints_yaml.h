// Design: reader/writer of the spec's joints.yaml (topology) and model.yaml (the same
// list with calibrated parameters, plus optional extra keys such as residuals and
// uncertainties). Load-time validation: unique joint names, type ball|hinge, parent and
// child naming bodies of the TargetSet and differing; for model.yaml the centres (and,
// for hinges, unit-normalisable axes) must be present and finite.
#pragma once

#include <string>
#include <utility>
#include <vector>

#include "core/expected.h"
#include "core/joint_type.h"
#include "core/types.h"
#include "formats/targets_yaml.h"

namespace mocap {

const char* joint_type_name(JointType t) noexcept;  // "ball" | "hinge"

struct JointSpec {
  std::string name;
  JointType type = JointType::kBall;
  std::string parent;
  std::string child;
  int parent_index = -1;  // index into TargetSet::bodies, filled at load
  int child_index = -1;

  bool calibrated = false;  // true when the parameters below are valid
  Vec3 center_parent = Vec3::Zero();
  Vec3 center_child = Vec3::Zero();
  Vec3 axis_parent = Vec3::UnitZ();  // hinge only, unit length
  Vec3 axis_child = Vec3::UnitZ();

  // Optional extra numeric keys of model.yaml (e.g. "residual_rms_mm": [0.4],
  // "center_parent_std_mm": [...]), written and read back in order.
  std::vector<std::pair<std::string, std::vector<double>>> extra;
  // Sets (replaces or appends) the extra key.
  void set_extra(const std::string& key, std::vector<double> values);
};

struct JointModel {
  std::vector<JointSpec> joints;
  int index_of(const std::string& name) const noexcept;
};

// joints.yaml: topology (calibrated parameters are read when present).
Expected<JointModel> load_joints(const std::string& path, const TargetSet& targets);
// model.yaml: every joint must carry its parameters.
Expected<JointModel> load_model(const std::string& path, const TargetSet& targets);
// Writes the topology, and the parameters of calibrated joints plus their extras.
Expected<void> save_model(const std::string& path, const JointModel& model);

}  // namespace mocap
