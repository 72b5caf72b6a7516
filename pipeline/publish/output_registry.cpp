// Design: see output_registry.h. The table below is the only list of outputs.
#include "pipeline/publish/output_registry.h"

#include <algorithm>
#include <cctype>

namespace mocap::publish {

Expected<int> OutputRequest::int_option(const char* key, int fallback, int lo, int hi) const {
  const std::string* v = option(key);
  if (v == nullptr) return fallback;
  if (v->empty() || v->size() > 6 || v->find_first_not_of("0123456789") != std::string::npos ||
      std::stoi(*v) < lo || std::stoi(*v) > hi) {
    return make_error(where, key,
                      "expected an integer " + std::to_string(lo) + ".." + std::to_string(hi) +
                          ", got '" + *v + "'");
  }
  return std::stoi(*v);
}

// One declaration + one table line per output (each defined in its own file).
extern const OutputKind kUdpOutput;      // udp_sink.cpp
extern const OutputKind kIceoryxOutput;  // iceoryx_sink.cpp
extern const OutputKind kVrpnOutput;     // vrpn/vrpn_sink.cpp
#ifdef MOCAP_HAVE_ROS2
extern const OutputKind kRos2Output;  // ros2/ros2_sink.cpp
#endif
#ifdef MOCAP_HAVE_FOXGLOVE
extern const OutputKind kFoxgloveOutput;  // foxglove (branch foxglove)
#endif

const std::vector<OutputKind>& output_kinds() {
  static const std::vector<OutputKind> kinds = {
      kUdpOutput,      kIceoryxOutput, kVrpnOutput,
#ifdef MOCAP_HAVE_ROS2
      kRos2Output,
#endif
#ifdef MOCAP_HAVE_FOXGLOVE
      kFoxgloveOutput,
#endif
  };
  return kinds;
}

const OutputKind* find_output_kind(const std::string& name) noexcept {
  for (const OutputKind& k : output_kinds())
    if (name == k.name) return &k;
  return nullptr;
}

Expected<bool> request_flag(const OutputRequest& r) {
  if (r.values.size() != 1)
    return make_error(r.where, "",
                      "expected true or false, got " + std::to_string(r.values.size()) + " values");
  std::string v = r.values[0];
  std::transform(v.begin(), v.end(), v.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  if (v == "true" || v == "yes" || v == "on" || v == "1") return true;
  if (v == "false" || v == "no" || v == "off" || v == "0") return false;
  return make_error(r.where, "", "expected true or false, got '" + r.values[0] + "'");
}

Expected<void> check_outputs(const std::vector<OutputRequest>& requests) {
  for (const OutputRequest& r : requests) {
    const OutputKind* k = find_output_kind(r.name);
    if (k == nullptr) {
      std::string known;
      for (const OutputKind& kind : output_kinds())
        known += (known.empty() ? "" : ", ") + std::string(kind.name);
      return make_error(r.where, "", "unknown output '" + r.name + "' (known: " + known + ")");
    }
    const std::string known = std::string(" ") + k->options + " ";
    for (const auto& [key, value] : r.options) {
      if (known.find(" " + key + " ") == std::string::npos) {
        const std::string list = k->options[0] != '\0' ? k->options : "none";
        return make_error(r.where, key, "unknown option (known: " + list + ")");
      }
    }
    if (auto c = k->check(r); !c) return c.error();
  }
  return {};
}

Expected<Outputs> create_outputs(const std::vector<OutputRequest>& requests,
                                 const OutputContext& context) {
  if (auto c = check_outputs(requests); !c) return c.error();
  Outputs out;
  for (const OutputRequest& r : requests) {
    auto created = find_output_kind(r.name)->create(r, context);
    if (!created) return created.error();
    if (!created->notice.empty()) out.notices.push_back(created->notice);
    if (created->sink) out.sinks.push_back(std::move(created->sink));
  }
  return out;
}

}  // namespace mocap::publish
