// Design: a free UDP port on 127.0.0.1 for tests that need one: a socket is bound to
// port 0 (the kernel picks an unused port), the port is read back and the socket is
// closed. Nobody listens on it afterwards until a test binds it, so it serves both as a
// destination nobody receives on and as the port of a test's own receivers.
#pragma once

#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

namespace mocap::test {

// An unused UDP port of 127.0.0.1, or -1 when no socket could be bound.
inline int free_udp_port() {
  const int fd = ::socket(AF_INET, SOCK_DGRAM, 0);
  if (fd < 0) return -1;
  sockaddr_in a{};
  a.sin_family = AF_INET;
  a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  socklen_t len = sizeof a;
  const bool ok = ::bind(fd, reinterpret_cast<sockaddr*>(&a), sizeof a) == 0 &&
                  ::getsockname(fd, reinterpret_cast<sockaddr*>(&a), &len) == 0;
  ::close(fd);
  return ok ? ntohs(a.sin_port) : -1;
}

}  // namespace mocap::test
