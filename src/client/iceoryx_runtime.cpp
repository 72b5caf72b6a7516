// Design: see iceoryx_runtime.h. A mutex serialises setup-time initialisation only.
#include "client/iceoryx_runtime.h"

#include <iceoryx_hoofs/log/logmanager.hpp>
#include <iceoryx_posh/runtime/posh_runtime.hpp>
#include <mutex>

#include "client/roudi_probe.h"

namespace mocap::client {

Expected<void> init_iceoryx_runtime(const std::string& app_name, const char* roudi_socket_path) {
  static std::mutex mutex;
  static bool initialised = false;
  const std::lock_guard<std::mutex> lock(mutex);
  if (initialised) return {};
  if (app_name.empty() || app_name.size() > 100 || app_name.find('/') != std::string::npos) {
    return make_error("iceoryx", "app name '" + app_name + "'",
                      "must be 1..100 characters without '/'");
  }
  if (!roudi_running(roudi_socket_path)) {
    return Error{"iceoryx: RouDi (iox-roudi) not running"};
  }
  // iceoryx logs registration details at debug level by default: keep warnings only.
  iox::log::LogManager::GetLogManager().SetDefaultLogLevel(iox::log::LogLevel::kWarn);
  iox::runtime::PoshRuntime::initRuntime(
      iox::RuntimeName_t(iox::cxx::TruncateToCapacity, app_name.c_str()));
  initialised = true;
  return {};
}

}  // namespace mocap::client
