// Design: the value checks of the run configuration that callers outside the YAML reader
// share (run_config.h): the CLI flags of `mocap run` (app/config_flags.h) go through the
// same range checks as the YAML keys, so there is one validation per value. Also the
// names of the enums as the configuration spells them.
#include <cstdio>
#include <string>

#include "config/config_reader.h"
#include "config/run_config.h"

namespace mocap::config_detail {

std::string host_port_problem(const std::string& value) {
  const std::size_t colon = value.rfind(':');
  if (colon == std::string::npos || colon == 0 || colon + 1 == value.size())
    return "expected HOST:PORT, got '" + value + "'";
  int port = 0;
  for (std::size_t i = colon + 1; i < value.size(); ++i) {
    if (value[i] < '0' || value[i] > '9' || port > 65535) return "bad port in '" + value + "'";
    port = port * 10 + (value[i] - '0');
  }
  if (port < 1 || port > 65535) return "port must be in 1..65535, got '" + value + "'";
  return {};
}

}  // namespace mocap::config_detail

namespace mocap::config {

const char* to_string(CameraBackend b) noexcept {
  switch (b) {
    case CameraBackend::kSim:
      return "sim";
    case CameraBackend::kReplay:
      return "replay";
    case CameraBackend::kV4l2:
      return "v4l2";
    case CameraBackend::kLibcamera:
      return "libcamera";
    case CameraBackend::kNode:
      return "node";
  }
  return "?";
}

const char* to_string(TriggerMode t) noexcept {
  switch (t) {
    case TriggerMode::kFreeRun:
      return "free_run";
    case TriggerMode::kExternal:
      return "external";
    case TriggerMode::kSoftware:
      return "software";
  }
  return "?";
}

RunConfig default_run_config() { return RunConfig{}; }

Expected<void> check_trigger_rate_hz(const std::string& where, double hz) {
  if (!(hz >= kMinTriggerRateHz && hz <= kMaxTriggerRateHz)) {
    char buf[96];
    std::snprintf(buf, sizeof buf, "must be in [%g, %g] Hz, got %g", kMinTriggerRateHz,
                  kMaxTriggerRateHz, hz);
    return make_error(where, "", buf);
  }
  return {};
}

Expected<void> check_loop_frames(const std::string& where, long long frames) {
  if (frames < kMinLoopFrames || frames > kMaxLoopFrames) {
    return make_error(where, "",
                      "must be in " + std::to_string(kMinLoopFrames) + ".." +
                          std::to_string(kMaxLoopFrames) + ", got " + std::to_string(frames));
  }
  return {};
}

Expected<void> check_host_port(const std::string& file, const std::string& where,
                               const std::string& value) {
  const std::string problem = config_detail::host_port_problem(value);
  if (!problem.empty()) return make_error(file, where, problem);
  return {};
}

}  // namespace mocap::config
