// Design: see iceoryx_runtime.h. A mutex serialises setup-time initialisation only.
#include "client/iceoryx_runtime.h"

#include <grp.h>

#include <iceoryx_hoofs/log/logmanager.hpp>
#include <iceoryx_posh/runtime/posh_runtime.hpp>
#include <mutex>
#include <string>

#include "client/roudi_probe.h"

namespace mocap::client {
namespace {

std::string group_name(gid_t gid) {
  const group* g = ::getgrgid(gid);  // set-up time only
  return (g != nullptr && g->gr_name != nullptr) ? "'" + std::string(g->gr_name) + "'"
                                                 : std::to_string(gid);
}

}  // namespace

Expected<void> init_iceoryx_runtime(const std::string& app_name, const char* roudi_socket_path) {
  static std::mutex mutex;
  static bool initialised = false;
  const std::lock_guard<std::mutex> lock(mutex);
  if (initialised) return {};
  if (app_name.empty() || app_name.size() > 100 || app_name.find('/') != std::string::npos) {
    return make_error("iceoryx", "app name '" + app_name + "'",
                      "must be 1..100 characters without '/'");
  }
  const RouDiProbe probe = probe_roudi(roudi_socket_path);
  switch (probe.status) {
    case RouDiStatus::kRunning:
      break;
    case RouDiStatus::kNotRunning:
      return Error{"iceoryx: RouDi (iox-roudi) not running"};
    case RouDiStatus::kNoPermission:
      return Error{"iceoryx: " + std::string(roudi_socket_path) +
                   ": permission denied (RouDi runs, but this user may not talk to it: "
                   "join RouDi's group and run with it as primary group, e.g. sg mocap -c ...)"};
    case RouDiStatus::kWrongGroup:
      // initRuntime would wait for a registration that never comes, then abort.
      return Error{
          "iceoryx: RouDi runs with group " + group_name(probe.roudi_gid) +
          " but this process's primary group is " + group_name(probe.process_gid) +
          " (iceoryx needs the same primary group: run it with sg/newgrp, or Group= in its unit)"};
  }
  // iceoryx logs registration details at debug level by default: keep warnings only.
  iox::log::LogManager::GetLogManager().SetDefaultLogLevel(iox::log::LogLevel::kWarn);
  iox::runtime::PoshRuntime::initRuntime(
      iox::RuntimeName_t(iox::cxx::TruncateToCapacity, app_name.c_str()));
  initialised = true;
  return {};
}

}  // namespace mocap::client
