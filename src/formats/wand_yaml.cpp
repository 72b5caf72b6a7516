// Design: wand.yaml reader/writer (see wand_yaml.h and docs/rig_calibration.md).
#include "formats/wand_yaml.h"

#include <cmath>
#include <cstdio>

#include "formats/text_io.h"
#include "formats/yaml_read.h"

namespace mocap {

using namespace formats_detail;

Expected<void> validate_wand(const WandSpec& wand, const std::string& file) {
  const auto& m = wand.markers_mm;
  if (m.size() < 3 || m.size() > 8)
    return make_error(file, "wand.markers_mm",
                      "needs 3..8 marker offsets, got " + std::to_string(m.size()));
  if (!(wand.marker_diameter_mm > 0.0))
    return make_error(file, "wand.marker_diameter_mm", "must be > 0 mm");
  for (std::size_t i = 0; i < m.size(); ++i) {
    if (!std::isfinite(m[i])) return make_error(file, "wand.markers_mm", "must be finite");
    if (i > 0 && !(m[i] - m[i - 1] >= wand.marker_diameter_mm * 1.5)) {
      char buf[160];
      std::snprintf(buf, sizeof buf,
                    "offsets must increase by at least 1.5 marker diameters (%.1f mm), "
                    "markers %zu and %zu are %.1f mm apart",
                    wand.marker_diameter_mm * 1.5, i - 1, i, m[i] - m[i - 1]);
      return make_error(file, "wand.markers_mm", buf);
    }
  }
  // The pattern read from the other end must differ, or the ends are ambiguous.
  const double len = m.back() - m.front();
  double asym = 0.0;
  for (std::size_t i = 0; i < m.size(); ++i) {
    const double r = (m[i] - m.front()) / len;
    const double r_rev = (m.back() - m[m.size() - 1 - i]) / len;
    asym = std::max(asym, std::fabs(r - r_rev));
  }
  if (asym < 0.1)
    return make_error(file, "wand.markers_mm",
                      "spacings are (nearly) symmetric: the wand's two ends cannot be told apart "
                      "(make one gap at least 10% of the length longer than its mirror)");
  return {};
}

Expected<void> validate_lframe(const LFrameSpec& lf, const std::string& file) {
  if (lf.markers_mm.size() < 3 || lf.markers_mm.size() > 8)
    return make_error(file, "lframe.markers_mm",
                      "needs 3..8 markers, got " + std::to_string(lf.markers_mm.size()));
  if (!(lf.marker_diameter_mm > 0.0))
    return make_error(file, "lframe.marker_diameter_mm", "must be > 0 mm");
  for (std::size_t i = 0; i < lf.markers_mm.size(); ++i) {
    for (std::size_t j = i + 1; j < lf.markers_mm.size(); ++j) {
      if ((lf.markers_mm[i] - lf.markers_mm[j]).norm() < 2.0 * lf.marker_diameter_mm)
        return make_error(file, "lframe.markers_mm",
                          "markers " + std::to_string(i) + " and " + std::to_string(j) +
                              " are closer than two marker diameters");
    }
  }
  const Vec3 a = lf.markers_mm[1] - lf.markers_mm[0];
  const Vec3 b = lf.markers_mm[2] - lf.markers_mm[0];
  if (a.cross(b).norm() < 0.05 * a.norm() * b.norm())
    return make_error(file, "lframe.markers_mm",
                      "the first three markers are (nearly) collinear: no axes can be set");
  return {};
}

Expected<CalibrationObjects> load_calibration_objects(const std::string& path) {
  auto root = load_yaml_map(path);
  if (!root) return root.error();
  auto r = guard<CalibrationObjects>(path, [&]() -> Expected<CalibrationObjects> {
    CalibrationObjects obj;
    const YAML::Node wand = require_key(*root, "", "wand");
    require_map(wand, "wand");
    obj.wand.markers_mm =
        get_doubles(require_key(wand, "wand", "markers_mm"), "wand.markers_mm", -1);
    if (has_key(wand, "marker_diameter_mm")) {
      obj.wand.marker_diameter_mm =
          get_double(require_key(wand, "wand", "marker_diameter_mm"), "wand.marker_diameter_mm");
    }
    if (has_key(*root, "lframe")) {
      const YAML::Node lf = require_key(*root, "", "lframe");
      require_map(lf, "lframe");
      obj.has_lframe = true;
      const YAML::Node list = require_key(lf, "lframe", "markers_mm");
      require_list(list, "lframe.markers_mm");
      for (std::size_t i = 0; i < list.size(); ++i) {
        obj.lframe.markers_mm.push_back(get_vec3(list[i], index_path("lframe.markers_mm", i)));
      }
      if (has_key(lf, "marker_diameter_mm")) {
        obj.lframe.marker_diameter_mm = get_double(require_key(lf, "lframe", "marker_diameter_mm"),
                                                   "lframe.marker_diameter_mm");
      }
    }
    return obj;
  });
  if (!r) return r.error();
  if (auto v = validate_wand(r->wand, path); !v) return v.error();
  if (r->has_lframe) {
    if (auto v = validate_lframe(r->lframe, path); !v) return v.error();
  }
  return r;
}

Expected<void> save_calibration_objects(const std::string& path, const CalibrationObjects& obj) {
  std::string s = "# Calibration objects (docs/rig_calibration.md), millimetres.\nwand:\n";
  s += "  marker_diameter_mm: ";
  append_double(s, obj.wand.marker_diameter_mm);
  s += "\n  markers_mm: [";
  for (std::size_t i = 0; i < obj.wand.markers_mm.size(); ++i) {
    if (i) s += ", ";
    append_double(s, obj.wand.markers_mm[i]);
  }
  s += "]\n";
  if (obj.has_lframe) {
    s += "lframe:\n  marker_diameter_mm: ";
    append_double(s, obj.lframe.marker_diameter_mm);
    s += "\n  markers_mm:\n";
    for (const Vec3& p : obj.lframe.markers_mm) {
      s += "    - [";
      append_double(s, p.x());
      s += ", ";
      append_double(s, p.y());
      s += ", ";
      append_double(s, p.z());
      s += "]\n";
    }
  }
  return write_text_file(path, s);
}

}  // namespace mocap
