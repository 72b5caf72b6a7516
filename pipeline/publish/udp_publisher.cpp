// Design: see udp_publisher.h.
#include "pipeline/publish/udp_publisher.h"

#include <sys/socket.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <utility>

#include "client/udp_endpoint.h"

namespace mocap::publish {

Expected<UdpPublisher> UdpPublisher::create(const std::vector<std::string>& destinations) {
  std::vector<sockaddr_in> addrs;
  addrs.reserve(destinations.size());
  for (const std::string& d : destinations) {
    auto addr = client::parse_udp_endpoint(d, "udp publisher");
    if (!addr) return addr.error();
    if (addr->sin_port == 0)
      return make_error("udp publisher", "'" + d + "'", "port 0 is not a destination");
    addrs.push_back(addr.value());
  }
  const int fd = ::socket(AF_INET, SOCK_DGRAM | SOCK_NONBLOCK | SOCK_CLOEXEC, 0);
  if (fd < 0) return Error{std::string("udp publisher: socket: ") + std::strerror(errno)};
  return UdpPublisher(fd, std::move(addrs));
}

UdpPublisher::UdpPublisher(int fd, std::vector<sockaddr_in> destinations) noexcept
    : fd_(fd), destinations_(std::move(destinations)) {}

UdpPublisher::UdpPublisher(UdpPublisher&& other) noexcept
    : fd_(std::exchange(other.fd_, -1)),
      destinations_(std::move(other.destinations_)),
      counters_(other.counters_) {}

UdpPublisher& UdpPublisher::operator=(UdpPublisher&& other) noexcept {
  if (this != &other) {
    if (fd_ >= 0) ::close(fd_);
    fd_ = std::exchange(other.fd_, -1);
    destinations_ = std::move(other.destinations_);
    counters_ = other.counters_;
  }
  return *this;
}

UdpPublisher::~UdpPublisher() {
  if (fd_ >= 0) ::close(fd_);
}

bool UdpPublisher::publish(const client::JointsMessage& msg) noexcept {
  ++counters_.messages;
  const std::size_t size = client::encode_datagram(msg, buf_.data(), buf_.size());
  if (size == 0) {
    ++counters_.encode_failures;
    return false;
  }
  bool all = true;
  for (const sockaddr_in& dest : destinations_) {
    const ssize_t n = ::sendto(fd_, buf_.data(), size, MSG_DONTWAIT | MSG_NOSIGNAL,
                               reinterpret_cast<const sockaddr*>(&dest), sizeof(dest));
    if (n == static_cast<ssize_t>(size)) {
      ++counters_.datagrams_sent;
      continue;
    }
    all = false;
    const int err = n < 0 ? errno : EMSGSIZE;
    if (err == EAGAIN || err == EWOULDBLOCK || err == ENOBUFS) {
      ++counters_.would_block;
    } else if (err == ECONNREFUSED) {
      ++counters_.refused;
    } else {
      ++counters_.other_errors;
    }
  }
  return all;
}

}  // namespace mocap::publish
