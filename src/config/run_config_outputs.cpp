// Design: the run configuration's `outputs:` map (docs/operations.md, "The configuration
// file"), kept apart from the main reader (run_config.cpp): udp (a list of HOST:PORT or
// {value, version, lead_ms}) and iceoryx (a flag or {value, lead_ms}) are read here into
// OutputSettings; every other key is a registry output (OutputEntry: its values and the
// options of the map form), checked later by pipeline/publish/output_registry. Errors are
// the reader's one line "FILE: key: problem (line N)".
#include <string>

#include "client/predict.h"
#include "config/config_reader.h"
#include "config/run_config.h"
#include "formats/yaml_read.h"

namespace mocap::config_detail {

using formats_detail::fail;
using formats_detail::index_path;
using formats_detail::line_suffix;

void read_outputs(const std::string& file, const YAML::Node& node, config::OutputSettings& o) {
  // The longest lead an output may predict by: the client library's prediction horizon.
  constexpr double kMaxOutputLeadMs = client::kDefaultPredictHorizonS * 1e3;
  // udp and iceoryx are read here; every other key is a registry output (OutputEntry),
  // checked by pipeline/publish/output_registry (resolve_run_config, --check-config).
  YAML::Node typed(YAML::NodeType::Map);
  if (node.IsDefined() && node.IsMap()) {
    formats_detail::check_unique_keys(node, "outputs");
    for (const auto& kv : node) {
      const std::string key = formats_detail::get_string(kv.first, "outputs");
      if (key == "udp" || key == "iceoryx") {
        typed[key] = kv.second;
        continue;
      }
      config::OutputEntry e;
      e.name = key;
      e.where = file + ": outputs." + key + line_suffix(kv.second);
      // reset(), never operator=: assigning a YAML::Node writes into the node it refers to.
      YAML::Node value;
      value.reset(kv.second);
      std::string path = "outputs." + key;
      if (kv.second.IsMap()) {  // {value: V, option: X, ...}
        formats_detail::check_unique_keys(kv.second, path);
        bool has_value = false;
        for (const auto& opt : kv.second) {
          const std::string k = formats_detail::get_string(opt.first, path);
          if (k == "value") {
            value.reset(opt.second);
            has_value = true;
            continue;
          }
          if (!opt.second.IsScalar())
            fail(path + "." + k, "expected a value, got " + formats_detail::describe(opt.second) +
                                     line_suffix(opt.second));
          e.options.emplace_back(k, formats_detail::get_string(opt.second, path + "." + k));
        }
        if (!has_value) fail(path, "the map form needs a 'value'" + line_suffix(kv.second));
        path += ".value";
      }
      if (value.IsSequence()) {
        for (std::size_t i = 0; i < value.size(); ++i)
          e.values.push_back(formats_detail::get_string(value[i], index_path(path, i)));
      } else if (value.IsScalar()) {
        e.values.push_back(formats_detail::get_string(value, path));
      } else {
        fail(path, "expected a value or a list of values, got " + formats_detail::describe(value) +
                       line_suffix(value));
      }
      o.more.push_back(std::move(e));
    }
  }
  const Section s(node.IsDefined() && node.IsMap() ? typed : node, "outputs", {"udp", "iceoryx"});
  if (s.has("udp")) {
    const YAML::Node list = s.node("udp");
    o.udp.clear();
    if (!list.IsNull()) {
      formats_detail::require_list(list, s.path("udp"));
      o.udp_versions.clear();
      o.udp_leads_ms.clear();
      for (std::size_t i = 0; i < list.size(); ++i) {
        const std::string where = index_path(s.path("udp"), i);
        std::uint16_t version = 1;
        double lead_ms = 0.0;
        YAML::Node item;  // reset(), never operator= (see above)
        item.reset(list[i]);
        if (list[i].IsMap()) {  // {value: HOST:PORT, version: 1 | 2, lead_ms: L}
          const Section m(list[i], where, {"value", "version", "lead_ms"});
          if (!m.has("value")) fail(where, "the map form needs a 'value'" + line_suffix(list[i]));
          if (const auto v = m.integer("version", 1, 2)) version = static_cast<std::uint16_t>(*v);
          if (const auto v = m.number("lead_ms", 0.0, kMaxOutputLeadMs)) lead_ms = *v;
          item.reset(m.node("value"));
        }
        const std::string v = formats_detail::get_string(item, where);
        const std::string problem = config_detail::host_port_problem(v);
        if (!problem.empty()) fail(where, problem + line_suffix(item));
        o.udp.push_back(v);
        o.udp_versions.push_back(version);
        o.udp_leads_ms.push_back(lead_ms);
      }
    }
  }
  if (s.has("iceoryx") && s.node("iceoryx").IsMap()) {  // {value: BOOL, lead_ms: L}
    const Section m(s.node("iceoryx"), s.path("iceoryx"), {"value", "lead_ms"});
    if (!m.has("value"))
      fail(s.path("iceoryx"), "the map form needs a 'value'" + line_suffix(s.node("iceoryx")));
    if (const auto on = m.flag("value")) o.iceoryx = *on;
    if (const auto v = m.number("lead_ms", 0.0, kMaxOutputLeadMs)) o.iceoryx_lead_ms = *v;
  } else {
    if (const auto on = s.flag("iceoryx")) o.iceoryx = *on;
  }
}

}  // namespace mocap::config_detail
