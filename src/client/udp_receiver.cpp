// Design: see udp_receiver.h. recv(MSG_TRUNC) reports the real datagram length, so a
// datagram larger than the buffer is detected (counted oversized + kBadLength) instead
// of being silently cut. ppoll(2) bounds wait(); the socket itself is non-blocking.
#include "client/udp_receiver.h"

#include <arpa/inet.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <utility>

#include "client/udp_endpoint.h"

namespace mocap::client {

std::uint64_t ReceiverCounters::rejected_total() const noexcept {
  std::uint64_t sum = 0;
  for (std::uint64_t v : rejected) sum += v;
  return sum;
}

Expected<UdpReceiver> UdpReceiver::create(const std::string& bind_host_port,
                                          const std::string& multicast_interface) {
  auto addr = parse_udp_endpoint(bind_host_port, "udp receiver");
  if (!addr) return addr.error();
  const auto fail = [&](int fd, const std::string& what, int err) -> Error {
    if (fd >= 0) ::close(fd);
    return make_error("udp receiver", "'" + bind_host_port + "'", what + ": " + std::strerror(err));
  };
  const bool multicast = IN_MULTICAST(ntohl(addr->sin_addr.s_addr));
  in_addr iface{};
  iface.s_addr = htonl(INADDR_ANY);
  if (!multicast_interface.empty() &&
      ::inet_pton(AF_INET, multicast_interface.c_str(), &iface) != 1) {
    return make_error("udp receiver", "multicast interface '" + multicast_interface + "'",
                      "not an IPv4 address");
  }
  const int fd = ::socket(AF_INET, SOCK_DGRAM | SOCK_NONBLOCK | SOCK_CLOEXEC, 0);
  if (fd < 0) return fail(-1, "socket", errno);
  if (multicast) {
    const int one = 1;
    if (::setsockopt(fd, SOL_SOCKET, SO_REUSEADDR, &one, sizeof one) != 0)
      return fail(fd, "SO_REUSEADDR", errno);
  }
  if (::bind(fd, reinterpret_cast<const sockaddr*>(&addr.value()), sizeof(sockaddr_in)) != 0)
    return fail(fd, "bind", errno);
  if (multicast) {
    ip_mreq mreq{};
    mreq.imr_multiaddr = addr->sin_addr;
    mreq.imr_interface = iface;
    if (::setsockopt(fd, IPPROTO_IP, IP_ADD_MEMBERSHIP, &mreq, sizeof mreq) != 0) {
      return fail(fd,
                  "join multicast group on " + (multicast_interface.empty()
                                                    ? std::string("the default interface")
                                                    : multicast_interface),
                  errno);
    }
  }
  sockaddr_in bound{};
  socklen_t bound_len = sizeof(bound);
  ::getsockname(fd, reinterpret_cast<sockaddr*>(&bound), &bound_len);
  return UdpReceiver(fd, ntohs(bound.sin_port), multicast);
}

UdpReceiver::UdpReceiver(UdpReceiver&& other) noexcept
    : fd_(std::exchange(other.fd_, -1)),
      port_(other.port_),
      multicast_(other.multicast_),
      counters_(other.counters_),
      latest_(other.latest_),
      scratch_(other.scratch_) {}

UdpReceiver& UdpReceiver::operator=(UdpReceiver&& other) noexcept {
  if (this != &other) {
    if (fd_ >= 0) ::close(fd_);
    fd_ = std::exchange(other.fd_, -1);
    port_ = other.port_;
    multicast_ = other.multicast_;
    counters_ = other.counters_;
    latest_ = other.latest_;
  }
  return *this;
}

UdpReceiver::~UdpReceiver() {
  if (fd_ >= 0) ::close(fd_);
}

void UdpReceiver::handle(std::size_t len) noexcept {
  ++counters_.datagrams;
  if (len > kMaxDatagramBytes) {
    ++counters_.oversized;
    ++counters_.rejected[static_cast<std::size_t>(DecodeStatus::kBadLength)];
    return;
  }
  const DecodeStatus status = decode_datagram(buf_.data(), len, scratch_, &scratch_version_);
  if (status != DecodeStatus::kOk) {
    ++counters_.rejected[static_cast<std::size_t>(status)];
    return;
  }
  if (counters_.accepted > 0) {
    if (scratch_.sequence <= latest_.sequence) {
      if (scratch_.capture_ns <= latest_.capture_ns) {
        ++counters_.stale;
        return;
      }
      ++counters_.restarts;  // new tracker run: sequence restarted, time moved on
    } else {
      counters_.dropped_frames += scratch_.sequence - latest_.sequence - 1;
    }
  }
  latest_ = scratch_;
  latest_version_ = scratch_version_;
  ++counters_.accepted;
}

int UdpReceiver::poll() noexcept {
  if (fd_ < 0) return 0;
  int accepted = 0;
  // Bounded: at most 4096 datagrams per call, so a flood cannot starve the caller.
  for (int i = 0; i < 4096; ++i) {
    const ssize_t n = ::recv(fd_, buf_.data(), buf_.size(), MSG_TRUNC | MSG_DONTWAIT);
    if (n < 0) {
      if (errno != EAGAIN && errno != EWOULDBLOCK && errno != EINTR) ++counters_.socket_errors;
      break;
    }
    const std::uint64_t before = counters_.accepted;
    handle(static_cast<std::size_t>(n));
    accepted += static_cast<int>(counters_.accepted - before);
  }
  return accepted;
}

int UdpReceiver::wait(std::chrono::microseconds timeout) noexcept {
  if (fd_ < 0) return 0;
  pollfd pfd{fd_, POLLIN, 0};
  const auto us = timeout.count() < 0 ? 0 : timeout.count();
  const timespec ts{static_cast<time_t>(us / 1'000'000),
                    static_cast<long>((us % 1'000'000) * 1000)};
  const int rc = ::ppoll(&pfd, 1, &ts, nullptr);  // microsecond resolution, unlike poll()
  if (rc < 0 && errno != EINTR) ++counters_.socket_errors;
  return poll();
}

}  // namespace mocap::client
