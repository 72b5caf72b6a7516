// Design: see roudi_probe.h. One socket()+connect()+close(), no allocation.
#include "client/roudi_probe.h"

#include <sys/socket.h>
#include <sys/un.h>
#include <unistd.h>

#include <cstring>

namespace mocap::client {

bool roudi_running(const char* socket_path) noexcept {
  if (socket_path == nullptr) return false;
  sockaddr_un addr{};
  addr.sun_family = AF_UNIX;
  const std::size_t n = std::strlen(socket_path);
  if (n == 0 || n >= sizeof(addr.sun_path)) return false;
  std::memcpy(addr.sun_path, socket_path, n + 1);
  const int fd = ::socket(AF_UNIX, SOCK_DGRAM | SOCK_CLOEXEC, 0);
  if (fd < 0) return false;
  const int rc = ::connect(fd, reinterpret_cast<const sockaddr*>(&addr), sizeof(addr));
  ::close(fd);
  return rc == 0;
}

}  // namespace mocap::client
