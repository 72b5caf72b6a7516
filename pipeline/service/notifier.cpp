// Design: see notifier.h.
#include "pipeline/service/notifier.h"

#include <systemd/sd-daemon.h>

#include <cstdlib>

namespace mocap::service {

SdNotifier::SdNotifier() noexcept {
  const char* socket = std::getenv("NOTIFY_SOCKET");
  active_ = socket != nullptr && socket[0] != '\0';
  std::uint64_t usec = 0;
  // > 0: $WATCHDOG_USEC is set and $WATCHDOG_PID (if set) is this process.
  if (sd_watchdog_enabled(0, &usec) > 0) watchdog_usec_ = usec;
}

bool SdNotifier::notify(const std::string& state) noexcept {
  if (!active_) return false;
  return sd_notify(0, state.c_str()) > 0;
}

}  // namespace mocap::service
