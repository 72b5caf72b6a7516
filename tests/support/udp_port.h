// Design: UDP on 127.0.0.1 for tests. free_udp_port(): a socket is bound to port 0 (the
// kernel picks an unused port), the port is read back and the socket is closed; nobody
// listens on it afterwards until a test binds it, so it serves both as a destination
// nobody receives on and as the port of a test's own receivers. KeepAllUdpSocket: a
// test's own receiver that keeps every datagram (a client::UdpReceiver keeps only the
// latest), for tests that check every frame the tracker sent.
#pragma once

#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <sys/time.h>
#include <unistd.h>

#include <cstddef>

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

class KeepAllUdpSocket {
 public:
  // Bound to 127.0.0.1 on a free port; receive() waits at most timeout_us. The receive
  // buffer (1 MiB) holds seconds of datagrams when the test thread is late.
  explicit KeepAllUdpSocket(long timeout_us) : fd_(::socket(AF_INET, SOCK_DGRAM, 0)) {
    if (fd_ < 0) return;
    sockaddr_in a{};
    a.sin_family = AF_INET;
    a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    socklen_t len = sizeof a;
    if (::bind(fd_, reinterpret_cast<sockaddr*>(&a), sizeof a) != 0 ||
        ::getsockname(fd_, reinterpret_cast<sockaddr*>(&a), &len) != 0)
      return;
    port_ = ntohs(a.sin_port);
    const int rcvbuf = 1 << 20;
    ::setsockopt(fd_, SOL_SOCKET, SO_RCVBUF, &rcvbuf, sizeof rcvbuf);
    timeval tv{timeout_us / 1'000'000, timeout_us % 1'000'000};
    ::setsockopt(fd_, SOL_SOCKET, SO_RCVTIMEO, &tv, sizeof tv);
  }
  KeepAllUdpSocket(const KeepAllUdpSocket&) = delete;
  KeepAllUdpSocket& operator=(const KeepAllUdpSocket&) = delete;
  ~KeepAllUdpSocket() {
    if (fd_ >= 0) ::close(fd_);
  }

  bool ok() const { return fd_ >= 0 && port_ > 0; }
  int port() const { return port_; }
  // The next datagram's size, or <= 0 when none came within the timeout.
  ssize_t receive(void* buf, std::size_t size) const { return ::recv(fd_, buf, size, 0); }

 private:
  int fd_;
  int port_ = 0;
};

}  // namespace mocap::test
