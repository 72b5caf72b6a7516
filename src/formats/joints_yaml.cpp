// Design: joints.yaml / model.yaml reader and writer (see joints_yaml.h and
// docs/formats.md). One parser serves both files; `require_params` decides whether the
// calibrated parameters are mandatory (model.yaml) or read only when present
// (joints.yaml). Keys of a joint other than the spec's are kept in JointSpec::extra
// when they are a number or a list of numbers, in file order, and written back as lists.
#include "formats/joints_yaml.h"

#include <cmath>
#include <set>

#include "formats/text_io.h"
#include "formats/yaml_read.h"

namespace mocap {
namespace {

using namespace formats_detail;

constexpr double kMinAxisNorm = 1e-9;        // shorter axes are "zero-length"
constexpr double kKeepAxisExactTol = 1e-12;  // |norm - 1| below this: kept bit for bit

bool is_spec_key(const std::string& k) {
  static const std::set<std::string> kKeys = {"name",        "type",          "parent",
                                              "child",       "center_parent", "center_child",
                                              "axis_parent", "axis_child"};
  return kKeys.count(k) != 0;
}

Vec3 read_axis(const YAML::Node& joint, const std::string& where, const char* key) {
  const YAML::Node n = require_key(joint, where, key);
  Vec3 a = get_vec3(n, key_path(where, key));
  const double norm = a.norm();
  if (norm < kMinAxisNorm) fail(key_path(where, key), "zero-length axis" + line_suffix(n));
  if (std::abs(norm - 1.0) > kKeepAxisExactTol) a /= norm;
  return a;
}

Expected<JointModel> load_joint_file(const std::string& path, const TargetSet& targets,
                                     bool require_params) {
  auto root = load_yaml_map(path);
  if (!root) return root.error();
  return guard<JointModel>(path, [&]() -> Expected<JointModel> {
    const YAML::Node joints = require_key(*root, "", "joints");
    require_list(joints, "joints");
    if (joints.size() == 0)
      fail("joints", "empty list (at least one joint is needed)" + line_suffix(joints));
    JointModel model;
    std::set<std::string> names;
    for (std::size_t j = 0; j < joints.size(); ++j) {
      const std::string where = index_path("joints", j);
      const YAML::Node node = joints[j];
      require_map(node, where);
      JointSpec spec;
      const YAML::Node name_node = require_key(node, where, "name");
      spec.name = get_string(name_node, key_path(where, "name"));
      if (const std::string p = name_problem(spec.name); !p.empty()) {
        fail(key_path(where, "name"), p + line_suffix(name_node));
      }
      if (!names.insert(spec.name).second) {
        fail(key_path(where, "name"),
             "duplicate joint name '" + spec.name + "'" + line_suffix(name_node));
      }
      const YAML::Node type_node = require_key(node, where, "type");
      const std::string type = get_string(type_node, key_path(where, "type"));
      if (type == "ball") {
        spec.type = JointType::kBall;
      } else if (type == "hinge") {
        spec.type = JointType::kHinge;
      } else {
        fail(key_path(where, "type"),
             "unknown joint type '" + type + "' (expected ball or hinge)" + line_suffix(type_node));
      }
      for (const char* side : {"parent", "child"}) {
        const YAML::Node n = require_key(node, where, side);
        const std::string body = get_string(n, key_path(where, side));
        const int index = targets.index_of(body);
        if (index < 0) {
          fail(key_path(where, side),
               "unknown body '" + body + "' (not in the targets file)" + line_suffix(n));
        }
        (side[0] == 'p' ? spec.parent : spec.child) = body;
        (side[0] == 'p' ? spec.parent_index : spec.child_index) = index;
      }
      if (spec.parent == spec.child) {
        fail(key_path(where, "child"),
             "parent and child are the same body '" + spec.child + "'" + line_suffix(node));
      }
      const bool has_center = has_key(node, "center_parent") || has_key(node, "center_child");
      if (require_params || has_center) {
        spec.center_parent =
            get_vec3(require_key(node, where, "center_parent"), key_path(where, "center_parent"));
        spec.center_child =
            get_vec3(require_key(node, where, "center_child"), key_path(where, "center_child"));
        if (spec.type == JointType::kHinge) {
          spec.axis_parent = read_axis(node, where, "axis_parent");
          spec.axis_child = read_axis(node, where, "axis_child");
        }
        spec.calibrated = true;
        for (const auto& kv : node) {
          const std::string key = kv.first.Scalar();
          if (is_spec_key(key)) continue;
          const YAML::Node& v = kv.second;
          double x = 0.0;
          if (v.IsScalar() && parse_double(v.Scalar(), x) == NumberStatus::kOk) {
            spec.extra.emplace_back(key, std::vector<double>{x});
          } else if (v.IsSequence()) {
            bool numeric = true;
            for (std::size_t i = 0; i < v.size() && numeric; ++i) {
              numeric = v[i].IsScalar() && parse_double(v[i].Scalar(), x) == NumberStatus::kOk;
            }
            if (numeric) spec.extra.emplace_back(key, get_doubles(v, key_path(where, key), -1));
          }
          // Anything else (text, maps, non-finite numbers) is an outside tool's key: ignored.
        }
      }
      model.joints.push_back(std::move(spec));
    }
    return model;
  });
}

void append_vec3(std::string& out, const char* key, const Vec3& v) {
  out += "    ";
  out += key;
  out += ": [";
  for (int k = 0; k < 3; ++k) {
    if (k) out += ", ";
    append_double(out, v[k]);
  }
  out += "]\n";
}

}  // namespace

const char* joint_type_name(JointType t) noexcept {
  return t == JointType::kHinge ? "hinge" : "ball";
}

void JointSpec::set_extra(const std::string& key, std::vector<double> values) {
  for (auto& [k, v] : extra) {
    if (k == key) {
      v = std::move(values);
      return;
    }
  }
  extra.emplace_back(key, std::move(values));
}

int JointModel::index_of(const std::string& name) const noexcept {
  for (std::size_t i = 0; i < joints.size(); ++i) {
    if (joints[i].name == name) return static_cast<int>(i);
  }
  return -1;
}

Expected<JointModel> load_joints(const std::string& path, const TargetSet& targets) {
  return load_joint_file(path, targets, false);
}

Expected<JointModel> load_model(const std::string& path, const TargetSet& targets) {
  return load_joint_file(path, targets, true);
}

Expected<void> save_model(const std::string& path, const JointModel& model) {
  for (const JointSpec& j : model.joints) {
    for (const auto& [key, values] : j.extra) {
      if (is_spec_key(key) || !name_problem(key).empty() || key.find(':') != std::string::npos ||
          key.find('#') != std::string::npos || key.find(' ') != std::string::npos) {
        return make_error(path, "joints." + j.name + "." + key, "extra key name not allowed");
      }
    }
  }
  std::string out =
      "# Joint model (mocap joints.yaml / model.yaml): centres in mm and unit axes, in the\n"
      "# parent and child body frames.\n"
      "joints:\n";
  for (const JointSpec& j : model.joints) {
    out += "  - name: " + yaml_string(j.name) + "\n";
    out += std::string("    type: ") + joint_type_name(j.type) + "\n";
    out += "    parent: " + yaml_string(j.parent) + "\n";
    out += "    child: " + yaml_string(j.child) + "\n";
    if (!j.calibrated) continue;
    append_vec3(out, "center_parent", j.center_parent);
    append_vec3(out, "center_child", j.center_child);
    if (j.type == JointType::kHinge) {
      append_vec3(out, "axis_parent", j.axis_parent);
      append_vec3(out, "axis_child", j.axis_child);
    }
    for (const auto& [key, values] : j.extra) {
      out += "    " + key + ": [";
      for (std::size_t i = 0; i < values.size(); ++i) {
        if (i) out += ", ";
        append_double(out, values[i]);
      }
      out += "]\n";
    }
  }
  return write_text_file(path, out);
}

}  // namespace mocap
