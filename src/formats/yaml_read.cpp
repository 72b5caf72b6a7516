// Design: see yaml_read.h.
#include "formats/yaml_read.h"

#include <set>

#include "formats/text_io.h"

namespace mocap::formats_detail {

Expected<YAML::Node> load_yaml_map(const std::string& path) {
  std::string text;
  if (auto r = read_text_file(path, text, kMaxYamlFileBytes); !r) return r.error();
  return guard<YAML::Node>(path, [&]() -> Expected<YAML::Node> {
    YAML::Node root = YAML::Load(text);
    if (!root.IsDefined() || root.IsNull()) return make_error(path, "", "empty file");
    if (!root.IsMap())
      fail("top level", "expected a map, got " + describe(root) + line_suffix(root));
    check_unique_keys(root, "top level");
    return root;
  });
}

std::string key_path(const std::string& parent, std::string_view key) {
  if (parent.empty()) return std::string(key);
  std::string s = parent;
  s += '.';
  s += key;
  return s;
}

std::string index_path(const std::string& parent, std::size_t index) {
  return parent + "[" + std::to_string(index) + "]";
}

std::string line_suffix(const YAML::Node& node) {
  if (!node.IsDefined()) return {};
  const YAML::Mark m = node.Mark();
  if (m.line < 0) return {};
  return " (line " + std::to_string(m.line + 1) + ")";
}

std::string describe(const YAML::Node& node) {
  if (!node.IsDefined() || node.IsNull()) return "nothing";
  if (node.IsMap()) return "a map";
  if (node.IsSequence()) return "a list";
  std::string s = node.Scalar();
  if (s.size() > 40) s = s.substr(0, 40) + "...";
  return "'" + s + "'";
}

void require_map(const YAML::Node& node, const std::string& where) {
  if (!node.IsMap()) fail(where, "expected a map, got " + describe(node) + line_suffix(node));
  check_unique_keys(node, where);
}

void require_list(const YAML::Node& node, const std::string& where) {
  if (!node.IsSequence()) fail(where, "expected a list, got " + describe(node) + line_suffix(node));
}

void check_unique_keys(const YAML::Node& map, const std::string& where) {
  std::set<std::string> seen;
  for (const auto& kv : map) {
    const std::string k = kv.first.IsScalar() ? kv.first.Scalar() : std::string("?");
    if (!seen.insert(k).second) {
      fail(key_path(where, k), "duplicate key" + line_suffix(kv.first));
    }
  }
}

bool has_key(const YAML::Node& map, std::string_view key) {
  if (!map.IsMap()) return false;
  for (const auto& kv : map) {
    if (kv.first.IsScalar() && kv.first.Scalar() == key) return true;
  }
  return false;
}

YAML::Node require_key(const YAML::Node& map, const std::string& where, std::string_view key) {
  for (const auto& kv : map) {
    if (kv.first.IsScalar() && kv.first.Scalar() == key) return kv.second;
  }
  fail(key_path(where, key), "missing key" + line_suffix(map));
}

double get_double(const YAML::Node& node, const std::string& where) {
  if (!node.IsScalar()) fail(where, "expected a number, got " + describe(node) + line_suffix(node));
  double v = 0.0;
  switch (parse_double(node.Scalar(), v)) {
    case NumberStatus::kOk:
      return v;
    case NumberStatus::kNotFinite:
      fail(where, "not a finite number: '" + node.Scalar() + "'" + line_suffix(node));
    case NumberStatus::kOutOfRange:
      fail(where, "number out of range: '" + node.Scalar() + "'" + line_suffix(node));
    case NumberStatus::kNotANumber:
      break;
  }
  fail(where, "expected a number, got " + describe(node) + line_suffix(node));
}

std::int64_t get_int(const YAML::Node& node, const std::string& where) {
  if (!node.IsScalar()) {
    fail(where, "expected an integer, got " + describe(node) + line_suffix(node));
  }
  std::int64_t v = 0;
  switch (parse_int64(node.Scalar(), v)) {
    case NumberStatus::kOk:
      return v;
    case NumberStatus::kOutOfRange:
      fail(where, "integer out of range: '" + node.Scalar() + "'" + line_suffix(node));
    default:
      break;
  }
  fail(where, "expected an integer, got " + describe(node) + line_suffix(node));
}

std::string get_string(const YAML::Node& node, const std::string& where) {
  if (!node.IsScalar()) fail(where, "expected a string, got " + describe(node) + line_suffix(node));
  return node.Scalar();
}

std::vector<double> get_doubles(const YAML::Node& node, const std::string& where, int count) {
  const std::string expect = count >= 0 ? "a list of " + std::to_string(count) + " numbers"
                                        : std::string("a list of numbers");
  if (!node.IsSequence())
    fail(where, "expected " + expect + ", got " + describe(node) + line_suffix(node));
  if (count >= 0 && node.size() != static_cast<std::size_t>(count)) {
    fail(where, "expected " + std::to_string(count) + " numbers, got " +
                    std::to_string(node.size()) + line_suffix(node));
  }
  std::vector<double> out;
  out.reserve(node.size());
  for (std::size_t i = 0; i < node.size(); ++i) {
    out.push_back(get_double(node[i], index_path(where, i)));
  }
  return out;
}

Vec3 get_vec3(const YAML::Node& node, const std::string& where) {
  const std::vector<double> v = get_doubles(node, where, 3);
  return Vec3(v[0], v[1], v[2]);
}

}  // namespace mocap::formats_detail
