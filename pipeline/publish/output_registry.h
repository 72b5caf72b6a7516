// Design: the ONE registry of the live tracker's outputs: a table (output_registry.cpp)
// name -> {check, create}, driven by the run configuration's `outputs:` map and the
// `mocap run` flags (--udp, --no-iceoryx, --ros2, --foxglove, ...). Adding an output is
// one file (its OutputSink and its two functions) plus one line in the table. Both
// functions are setup code: check() validates a request without opening anything (for
// `mocap run --check-config`), create() builds the sink. A sink whose transport is
// missing at runtime (no iox-roudi, no DDS network) is not an error: create() returns
// no sink and a one-line notice, and the tracker runs on without it.
#pragma once

#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "core/expected.h"
#include "pipeline/publish/output_sink.h"

namespace mocap::publish {

struct OutputRequest {
  std::string name;                 // registry key: "udp", "iceoryx", "ros2", "foxglove", ...
  std::vector<std::string> values;  // outputs.NAME: a scalar is one value, a list many
  std::string where;                // prefix of error messages, e.g. "run.yaml: outputs.ros2"
  // Further settings a flag gives (e.g. "multicast_if", "multicast_ttl" for udp).
  std::vector<std::pair<std::string, std::string>> options;

  const std::string* option(const std::string& key) const noexcept {
    for (const auto& [k, v] : options)
      if (k == key) return &v;
    return nullptr;
  }
  // Option `key` as an integer in lo..hi (decimal digits only); `fallback` when it is not
  // given; else "<where>: <key>: expected an integer lo..hi, got '<value>'".
  Expected<int> int_option(const char* key, int fallback, int lo, int hi) const;
};

struct OutputCreated {
  std::unique_ptr<OutputSink> sink;  // null: not active (see notice)
  std::string notice;                // one line to print once, or empty
};

struct OutputKind {
  const char* name;
  const char* summary;  // one line for help and docs
  const char* options;  // the option keys it accepts, space-separated ("" if none)
  Expected<void> (*check)(const OutputRequest& request);
  Expected<OutputCreated> (*create)(const OutputRequest& request, const OutputContext& context);
};

// The table (every output built into this binary).
const std::vector<OutputKind>& output_kinds();
const OutputKind* find_output_kind(const std::string& name) noexcept;

// "true"/"false" (also yes/no, on/off, 1/0) of a one-value request; error names `where`.
Expected<bool> request_flag(const OutputRequest& request);

// check() of every request (unknown names included: "...: unknown output 'x' (known: ...)";
// unknown option keys: "...: outputs.foxglove.max_client: unknown option (known: ...)").
Expected<void> check_outputs(const std::vector<OutputRequest>& requests);

// Builds every request in order; notices (one line each) are appended to `notices`.
struct Outputs {
  std::vector<std::unique_ptr<OutputSink>> sinks;
  std::vector<std::string> notices;
  std::vector<OutputSink*> list() const {
    std::vector<OutputSink*> v;
    for (const auto& s : sinks) v.push_back(s.get());
    return v;
  }
};
Expected<Outputs> create_outputs(const std::vector<OutputRequest>& requests,
                                 const OutputContext& context);

}  // namespace mocap::publish
