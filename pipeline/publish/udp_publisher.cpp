// Design: see udp_publisher.h.
#include "pipeline/publish/udp_publisher.h"

#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <string>
#include <utility>

#include "client/udp_endpoint.h"

namespace mocap::publish {

Expected<UdpPublisher> UdpPublisher::create(const std::vector<std::string>& destinations,
                                            const UdpMulticastOptions& multicast,
                                            const std::vector<std::uint16_t>& versions) {
  if (!versions.empty() && versions.size() != destinations.size())
    return make_error("udp publisher", "versions", "one per destination");
  for (const std::uint16_t v : versions) {
    if (v != client::kDatagramVersion && v != client::kDatagramVersion2)
      return make_error("udp publisher", "version " + std::to_string(v), "must be 1 or 2");
  }
  std::vector<sockaddr_in> addrs;
  bool any_multicast = false;
  addrs.reserve(destinations.size());
  for (const std::string& d : destinations) {
    auto addr = client::parse_udp_endpoint(d, "udp publisher");
    if (!addr) return addr.error();
    if (addr->sin_port == 0)
      return make_error("udp publisher", "'" + d + "'", "port 0 is not a destination");
    any_multicast = any_multicast || IN_MULTICAST(ntohl(addr->sin_addr.s_addr));
    addrs.push_back(addr.value());
  }
  if (multicast.ttl < 0 || multicast.ttl > 255)
    return make_error("udp publisher", "multicast ttl", "must be in 0..255");
  in_addr iface{};
  if (!multicast.interface.empty() &&
      ::inet_pton(AF_INET, multicast.interface.c_str(), &iface) != 1) {
    return make_error("udp publisher", "multicast interface '" + multicast.interface + "'",
                      "not an IPv4 address");
  }
  const int fd = ::socket(AF_INET, SOCK_DGRAM | SOCK_NONBLOCK | SOCK_CLOEXEC, 0);
  if (fd < 0) return Error{std::string("udp publisher: socket: ") + std::strerror(errno)};
  // One destination (the default): connect to it, so that the kernel drops datagrams
  // from any other sender; the tracker never reads, and with several destinations the
  // unread receive queue is bounded by the minimum buffer instead (docs/reliability.md).
  // Best effort: sendto() below works either way.
  if (addrs.size() == 1) {
    (void)::connect(fd, reinterpret_cast<const sockaddr*>(&addrs[0]), sizeof(addrs[0]));
  } else {
    const int min_rcvbuf = 1;  // the kernel rounds up to its minimum
    (void)::setsockopt(fd, SOL_SOCKET, SO_RCVBUF, &min_rcvbuf, sizeof min_rcvbuf);
  }
  std::vector<std::uint16_t> vers = versions;
  vers.resize(addrs.size(), client::kDatagramVersion);
  UdpPublisher pub(fd, std::move(addrs), std::move(vers));  // owns fd from here
  if (any_multicast) {
    const auto set = [&](int option, const void* value, socklen_t len,
                         const char* what) -> Expected<void> {
      if (::setsockopt(fd, IPPROTO_IP, option, value, len) == 0) return {};
      return make_error("udp publisher", what, std::strerror(errno));
    };
    const int ttl = multicast.ttl;
    const int loop = multicast.loop ? 1 : 0;
    if (auto r = set(IP_MULTICAST_TTL, &ttl, sizeof ttl, "IP_MULTICAST_TTL"); !r) return r.error();
    if (auto r = set(IP_MULTICAST_LOOP, &loop, sizeof loop, "IP_MULTICAST_LOOP"); !r)
      return r.error();
    if (!multicast.interface.empty()) {
      if (auto r = set(IP_MULTICAST_IF, &iface, sizeof iface,
                       ("IP_MULTICAST_IF " + multicast.interface).c_str());
          !r)
        return r.error();
    }
  }
  return pub;
}

UdpPublisher::UdpPublisher(int fd, std::vector<sockaddr_in> destinations,
                           std::vector<std::uint16_t> versions) noexcept
    : fd_(fd), destinations_(std::move(destinations)), versions_(std::move(versions)) {}

UdpPublisher::UdpPublisher(UdpPublisher&& other) noexcept
    : fd_(std::exchange(other.fd_, -1)),
      destinations_(std::move(other.destinations_)),
      versions_(std::move(other.versions_)),
      counters_(other.counters_) {}

UdpPublisher& UdpPublisher::operator=(UdpPublisher&& other) noexcept {
  if (this != &other) {
    if (fd_ >= 0) ::close(fd_);
    fd_ = std::exchange(other.fd_, -1);
    destinations_ = std::move(other.destinations_);
    versions_ = std::move(other.versions_);
    counters_ = other.counters_;
  }
  return *this;
}

UdpPublisher::~UdpPublisher() {
  if (fd_ >= 0) ::close(fd_);
}

UdpPublisher::Status UdpPublisher::publish(const client::JointsMessage& msg) noexcept {
  ++counters_.messages;
  // Each version used is encoded once per message.
  std::size_t size_v1 = 0, size_v2 = 0;
  for (const std::uint16_t v : versions_) {
    if (v == client::kDatagramVersion2 && size_v2 == 0)
      size_v2 = client::encode_datagram(msg, buf_v2_.data(), buf_v2_.size(), v);
    if (v == client::kDatagramVersion && size_v1 == 0)
      size_v1 = client::encode_datagram(msg, buf_.data(), buf_.size(), v);
  }
  if (size_v1 == 0 && size_v2 == 0) {
    ++counters_.encode_failures;
    return Status::kFailed;
  }
  Status status = Status::kSent;
  const auto send = [&](const sockaddr_in& dest, const std::uint8_t* data,
                        std::size_t size) noexcept -> int {
    const ssize_t n = ::sendto(fd_, data, size, MSG_DONTWAIT | MSG_NOSIGNAL,
                               reinterpret_cast<const sockaddr*>(&dest), sizeof(dest));
    return n == static_cast<ssize_t>(size) ? 0 : (n < 0 ? errno : EMSGSIZE);
  };
  for (std::size_t i = 0; i < destinations_.size(); ++i) {
    const sockaddr_in& dest = destinations_[i];
    const bool v2 = versions_[i] == client::kDatagramVersion2;
    const std::uint8_t* data = v2 ? buf_v2_.data() : buf_.data();
    const std::size_t size = v2 ? size_v2 : size_v1;
    int err = send(dest, data, size);
    const bool refused = err == ECONNREFUSED;
    if (refused) err = send(dest, data, size);  // the report cleared the error: send this one
    if (err == 0) {
      ++counters_.datagrams_sent;
      if (refused) {
        ++counters_.no_listener;
        if (status == Status::kSent) status = Status::kSentNoListener;
      }
      continue;
    }
    status = Status::kFailed;
    if (err == EAGAIN || err == EWOULDBLOCK || err == ENOBUFS) {
      ++counters_.would_block;
    } else if (err == ECONNREFUSED) {
      ++counters_.refused;
    } else {
      ++counters_.other_errors;
    }
  }
  return status;
}

}  // namespace mocap::publish
