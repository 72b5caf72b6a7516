// Design: see roudi_probe.h. One stat(), socket()+connect()+close(), no allocation.
#include "client/roudi_probe.h"

#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/un.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

namespace mocap::client {

RouDiProbe probe_roudi(const char* socket_path) noexcept {
  RouDiProbe p;
  p.process_gid = ::getegid();
  if (socket_path == nullptr) return p;
  sockaddr_un addr{};
  addr.sun_family = AF_UNIX;
  const std::size_t n = std::strlen(socket_path);
  if (n == 0 || n >= sizeof(addr.sun_path)) return p;
  std::memcpy(addr.sun_path, socket_path, n + 1);
  struct stat st {};
  if (::stat(socket_path, &st) != 0) return p;
  p.roudi_gid = st.st_gid;
  const int fd = ::socket(AF_UNIX, SOCK_DGRAM | SOCK_CLOEXEC, 0);
  if (fd < 0) return p;
  const int rc = ::connect(fd, reinterpret_cast<const sockaddr*>(&addr), sizeof(addr));
  const int err = errno;
  ::close(fd);
  if (rc != 0) {
    p.status =
        (err == EACCES || err == EPERM) ? RouDiStatus::kNoPermission : RouDiStatus::kNotRunning;
    return p;
  }
  p.status = p.roudi_gid == p.process_gid ? RouDiStatus::kRunning : RouDiStatus::kWrongGroup;
  return p;
}

bool roudi_running(const char* socket_path) noexcept {
  const RouDiStatus s = probe_roudi(socket_path).status;
  return s == RouDiStatus::kRunning || s == RouDiStatus::kWrongGroup;
}

}  // namespace mocap::client
