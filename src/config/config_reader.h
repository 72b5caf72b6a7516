// Design: strict, typed access to one YAML map of the run configuration (internal to
// mocap_config). A Section is built with the list of keys it accepts and rejects any
// other key at once ("cameras[0].exposure: unknown key (line 7); expected one of: ..."),
// so a typo is never silently ignored. The typed getters return std::nullopt when the
// key is absent and throw formats_detail::FieldError (converted to the one-line
// "FILE: key: problem" at the loader's boundary) when the value is malformed or out of
// range; ranges are inclusive unless stated.
#pragma once

#include <yaml-cpp/yaml.h>

#include <cstdint>
#include <initializer_list>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace mocap::config_detail {

class Section {
 public:
  // `node` must be a map (or absent/null: an empty section). Throws on unknown keys.
  Section(const YAML::Node& node, std::string where, std::initializer_list<std::string_view> keys)
      : Section(node, std::move(where),
                std::span<const std::string_view>(keys.begin(), keys.size())) {}
  // The same with keys built at run time (e.g. one per camera).
  Section(const YAML::Node& node, std::string where, std::span<const std::string_view> keys);

  const std::string& where() const noexcept { return where_; }
  bool has(std::string_view key) const;
  YAML::Node node(std::string_view key) const;  // undefined when absent
  std::string path(std::string_view key) const;
  std::string line(std::string_view key) const;  // " (line N)" of the value, or ""

  std::optional<double> number(std::string_view key, double lo, double hi) const;
  std::optional<std::int64_t> integer(std::string_view key, std::int64_t lo, std::int64_t hi) const;
  std::optional<bool> flag(std::string_view key) const;
  std::optional<std::string> text(std::string_view key) const;  // non-empty
  // One of `choices` (exact spelling); the error lists them.
  template <class E>
  std::optional<E> choice(std::string_view key,
                          std::initializer_list<std::pair<std::string_view, E>> choices) const {
    const std::optional<std::string> s = text(key);
    if (!s) return std::nullopt;
    std::string list;
    for (const auto& [name, value] : choices) {
      if (*s == name) return value;
      list += (list.empty() ? "" : "|") + std::string(name);
    }
    bad(key, "expected " + list + ", got '" + *s + "'");
  }
  [[noreturn]] void bad(std::string_view key, const std::string& problem) const;

 private:
  YAML::Node map_;
  std::string where_;
};

}  // namespace mocap::config_detail

namespace mocap::config {
struct CameraSettings;
struct NodeSettings;
struct OutputSettings;
struct PipelineSettings;
}  // namespace mocap::config

namespace mocap::config_detail {

// The camera-node keys (run_config_nodes.cpp): a camera's `trigger` (free_run | external |
// software | central), replay `camera: NAME`; the `node:` section; pipeline.pair_by and
// pair_tolerance_us.
void read_node_camera_keys(const Section& s, config::CameraSettings& cam);
// `cameras`: the configuration's (read before), for node.detect_threads' check.
void read_node_section(const YAML::Node& node, const std::vector<config::CameraSettings>& cameras,
                       config::NodeSettings& n);
void read_pair_keys(const Section& s, config::PipelineSettings& p);

// The `outputs:` map (run_config_outputs.cpp); `file` prefixes the registry outputs' errors.
void read_outputs(const std::string& file, const YAML::Node& node, config::OutputSettings& o);

// Empty when `value` is a valid HOST:PORT, else the problem (run_config_checks.cpp).
std::string host_port_problem(const std::string& value);

}  // namespace mocap::config_detail
