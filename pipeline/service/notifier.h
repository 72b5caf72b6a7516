// Design: the service manager's notification channel. Notifier is the interface the
// Supervisor talks to (tests substitute a recorder); SdNotifier is the real one, built
// on libsystemd's sd_notify(3) / sd_watchdog_enabled(3) (linked through pkg-config
// `libsystemd`): READY=1, WATCHDOG=1, STATUS=..., STOPPING=1 as datagrams to
// $NOTIFY_SOCKET, and the watchdog period from $WATCHDOG_USEC (+ $WATCHDOG_PID, which
// must be this process: ExecStart runs `mocap` directly). Without $NOTIFY_SOCKET (not
// under systemd) every call is a no-op. Called from the main thread only, never from a
// pipeline stage.
#pragma once

#include <cstdint>
#include <string>

namespace mocap::service {

class Notifier {
 public:
  virtual ~Notifier() = default;
  // One notification ("READY=1", "WATCHDOG=1", "STATUS=..."); false when not sent.
  virtual bool notify(const std::string& state) noexcept = 0;
  // The service manager's watchdog timeout in microseconds; 0: no watchdog.
  virtual std::uint64_t watchdog_usec() const noexcept = 0;
};

class SdNotifier final : public Notifier {
 public:
  SdNotifier() noexcept;
  bool notify(const std::string& state) noexcept override;
  std::uint64_t watchdog_usec() const noexcept override { return watchdog_usec_; }
  // True when $NOTIFY_SOCKET is set (running under a service manager).
  bool active() const noexcept { return active_; }

 private:
  std::uint64_t watchdog_usec_ = 0;
  bool active_ = false;
};

}  // namespace mocap::service
