// Design: targets.yaml reader/writer (see targets_yaml.h and docs/formats.md).
#include "formats/targets_yaml.h"

#include <cstdio>
#include <set>

#include "formats/text_io.h"
#include "formats/yaml_read.h"

namespace mocap {

using namespace formats_detail;

int TargetSet::index_of(const std::string& name) const noexcept {
  for (std::size_t i = 0; i < bodies.size(); ++i) {
    if (bodies[i].name == name) return static_cast<int>(i);
  }
  return -1;
}

Expected<TargetSet> load_targets(const std::string& path) {
  auto root = load_yaml_map(path);
  if (!root) return root.error();
  return guard<TargetSet>(path, [&]() -> Expected<TargetSet> {
    TargetSet set;
    if (has_key(*root, "marker_diameter")) {
      const YAML::Node n = require_key(*root, "", "marker_diameter");
      set.marker_diameter_mm = get_double(n, "marker_diameter");
      if (!(set.marker_diameter_mm > 0.0)) {
        fail("marker_diameter",
             "must be > 0 mm, got " + format_double(set.marker_diameter_mm) + line_suffix(n));
      }
    }
    const YAML::Node bodies = require_key(*root, "", "bodies");
    require_list(bodies, "bodies");
    if (bodies.size() == 0)
      fail("bodies", "empty list (at least one body is needed)" + line_suffix(bodies));
    std::set<std::string> names;
    for (std::size_t b = 0; b < bodies.size(); ++b) {
      const std::string where = index_path("bodies", b);
      const YAML::Node body = bodies[b];
      require_map(body, where);
      MarkerTarget target;
      const YAML::Node name_node = require_key(body, where, "name");
      target.name = get_string(name_node, key_path(where, "name"));
      if (const std::string p = name_problem(target.name); !p.empty()) {
        fail(key_path(where, "name"), p + line_suffix(name_node));
      }
      if (!names.insert(target.name).second) {
        fail(key_path(where, "name"),
             "duplicate body name '" + target.name + "'" + line_suffix(name_node));
      }
      const std::string mwhere = key_path(where, "markers");
      const YAML::Node markers = require_key(body, where, "markers");
      require_list(markers, mwhere);
      if (markers.size() < 3) {
        fail(mwhere, "body '" + target.name + "' has " + std::to_string(markers.size()) +
                         " markers, at least 3 are needed" + line_suffix(markers));
      }
      for (std::size_t m = 0; m < markers.size(); ++m) {
        target.markers_body.push_back(get_vec3(markers[m], index_path(mwhere, m)));
      }
      for (std::size_t i = 0; i < target.markers_body.size(); ++i) {
        for (std::size_t j = i + 1; j < target.markers_body.size(); ++j) {
          const double d = (target.markers_body[i] - target.markers_body[j]).norm();
          if (d < set.marker_diameter_mm) {
            char buf[200];
            std::snprintf(buf, sizeof buf,
                          "markers %zu and %zu of body '%s' are %.3f mm apart, closer than the "
                          "marker diameter %.3f mm",
                          i, j, target.name.c_str(), d, set.marker_diameter_mm);
            fail(mwhere, buf + line_suffix(markers[j]));
          }
        }
      }
      set.bodies.push_back(std::move(target));
    }
    return set;
  });
}

Expected<void> save_targets(const std::string& path, const TargetSet& targets) {
  std::string out =
      "# Rigid marker targets (mocap targets.yaml): marker centres in mm, body frame.\n";
  out += "marker_diameter: ";
  append_double(out, targets.marker_diameter_mm);
  out += "\nbodies:\n";
  for (const MarkerTarget& t : targets.bodies) {
    out += "  - name: " + yaml_string(t.name) + "\n    markers:\n";
    for (const Vec3& m : t.markers_body) {
      out += "      - [";
      for (int k = 0; k < 3; ++k) {
        if (k) out += ", ";
        append_double(out, m[k]);
      }
      out += "]\n";
    }
  }
  return write_text_file(path, out);
}

}  // namespace mocap
