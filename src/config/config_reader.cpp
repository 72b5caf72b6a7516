// Design: see config_reader.h.
#include "config/config_reader.h"

#include <cmath>
#include <cstdio>

#include "formats/text_io.h"
#include "formats/yaml_read.h"

namespace mocap::config_detail {

using namespace mocap::formats_detail;

namespace {

std::string num(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g", v);
  return buf;
}

}  // namespace

Section::Section(const YAML::Node& node, std::string where, std::span<const std::string_view> keys)
    : map_(node), where_(std::move(where)) {
  if (!node.IsDefined() || node.IsNull()) {
    map_ = YAML::Node(YAML::NodeType::Map);
    return;
  }
  require_map(node, where_);
  for (const auto& kv : node) {
    const std::string k = kv.first.IsScalar() ? kv.first.Scalar() : std::string("?");
    bool known = false;
    for (std::string_view allowed : keys) known = known || k == allowed;
    if (!known) {
      std::string list;
      for (std::string_view allowed : keys)
        list += (list.empty() ? "" : ", ") + std::string(allowed);
      fail(key_path(where_, k),
           "unknown key" + line_suffix(kv.first) + "; expected one of: " + list);
    }
  }
}

bool Section::has(std::string_view key) const { return has_key(map_, key); }

YAML::Node Section::node(std::string_view key) const {
  for (const auto& kv : map_) {
    if (kv.first.IsScalar() && kv.first.Scalar() == key) return kv.second;
  }
  return YAML::Node(YAML::NodeType::Undefined);
}

std::string Section::path(std::string_view key) const { return key_path(where_, key); }

std::string Section::line(std::string_view key) const { return line_suffix(node(key)); }

void Section::bad(std::string_view key, const std::string& problem) const {
  fail(path(key), problem + line(key));
}

std::optional<double> Section::number(std::string_view key, double lo, double hi) const {
  if (!has(key)) return std::nullopt;
  const double v = get_double(node(key), path(key));
  if (v < lo || v > hi) bad(key, "must be in [" + num(lo) + ", " + num(hi) + "], got " + num(v));
  return v;
}

std::optional<std::int64_t> Section::integer(std::string_view key, std::int64_t lo,
                                             std::int64_t hi) const {
  if (!has(key)) return std::nullopt;
  const std::int64_t v = get_int(node(key), path(key));
  if (v < lo || v > hi) {
    bad(key, "must be in [" + std::to_string(lo) + ", " + std::to_string(hi) + "], got " +
                 std::to_string(v));
  }
  return v;
}

std::optional<bool> Section::flag(std::string_view key) const {
  if (!has(key)) return std::nullopt;
  const YAML::Node n = node(key);
  if (n.IsScalar()) {
    const std::string& s = n.Scalar();
    if (s == "true") return true;
    if (s == "false") return false;
  }
  bad(key, "expected true or false, got " + describe(n));
}

std::optional<std::string> Section::text(std::string_view key) const {
  if (!has(key)) return std::nullopt;
  std::string s = get_string(node(key), path(key));
  if (s.empty()) bad(key, "must not be empty");
  return s;
}

}  // namespace mocap::config_detail
