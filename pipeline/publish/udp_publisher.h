// Design: tracker side of the UDP transport. create() resolves every "HOST:PORT"
// destination once and opens ONE non-blocking IPv4 socket (never bound to a listening
// port: the tracker sends only). publish() encodes the datagram (version 1, or 2 for the
// destinations configured so) into preallocated buffers and sendto()s each destination
// with MSG_DONTWAIT: noexcept, allocation-free,
// no logging; transient errors (EAGAIN/ENOBUFS/ECONNREFUSED, ...) are only counted.
// Multicast: when a destination is a multicast group (224.0.0.0/4), setup sets
// IP_MULTICAST_TTL (hops, default 1: the local network), IP_MULTICAST_LOOP (default on:
// consumers on this machine receive too) and, when given, IP_MULTICAST_IF (the local
// interface address to send from; otherwise the kernel routes the group).
#pragma once

#include <netinet/in.h>

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "client/datagram.h"
#include "client/joints_message.h"
#include "core/expected.h"

namespace mocap::publish {

struct UdpPublisherCounters {
  std::uint64_t messages = 0;         // publish() calls
  std::uint64_t datagrams_sent = 0;   // successful sendto()s (messages x destinations)
  std::uint64_t no_listener = 0;      // datagrams sent while the destination had no listener
  std::uint64_t encode_failures = 0;  // joint_count > kMaxJoints
  std::uint64_t would_block = 0;      // EAGAIN/EWOULDBLOCK/ENOBUFS: socket buffer full
  std::uint64_t refused = 0;          // ECONNREFUSED twice in a row: the datagram was lost
  std::uint64_t other_errors = 0;     // any other errno
};

struct UdpMulticastOptions {
  int ttl = 1;            // IP_MULTICAST_TTL, 0..255
  bool loop = true;       // IP_MULTICAST_LOOP
  std::string interface;  // IP_MULTICAST_IF: IPv4 address of a local interface; empty: route
};

class UdpPublisher {
 public:
  // Fails with one line, e.g. "udp publisher: 'host:99999': port must be 0..65535".
  // versions: the datagram version of each destination (1 or 2); empty: all version 1.
  static Expected<UdpPublisher> create(const std::vector<std::string>& destinations,
                                       const UdpMulticastOptions& multicast = {},
                                       const std::vector<std::uint16_t>& versions = {});

  UdpPublisher(UdpPublisher&& other) noexcept;
  UdpPublisher& operator=(UdpPublisher&& other) noexcept;
  UdpPublisher(const UdpPublisher&) = delete;
  UdpPublisher& operator=(const UdpPublisher&) = delete;
  ~UdpPublisher();

  enum class Status : std::uint8_t {
    kSent,            // every destination took the datagram
    kSentNoListener,  // sent everywhere, but a destination reported no listener (ICMP)
    kFailed,          // at least one destination's datagram was not sent (counted)
  };
  // A connected UDP socket reports the ICMP port unreachable of an earlier datagram as
  // ECONNREFUSED on the next sendto(), which then sends nothing; the report clears the
  // error, so the datagram is sent again once: a tracker without a listener yet keeps
  // sending every frame (two syscalls per frame) and a listener that starts gets all.
  Status publish(const client::JointsMessage& msg) noexcept;

  std::size_t destination_count() const noexcept { return destinations_.size(); }
  const UdpPublisherCounters& counters() const noexcept { return counters_; }

 private:
  UdpPublisher(int fd, std::vector<sockaddr_in> destinations,
               std::vector<std::uint16_t> versions) noexcept;

  int fd_ = -1;
  std::vector<sockaddr_in> destinations_;  // fixed after create()
  std::vector<std::uint16_t> versions_;    // per destination
  UdpPublisherCounters counters_{};
  std::array<std::uint8_t, client::kMaxDatagramBytes> buf_{};     // version 1
  std::array<std::uint8_t, client::kMaxDatagramBytes> buf_v2_{};  // version 2
};

}  // namespace mocap::publish
