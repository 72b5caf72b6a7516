// Design: the motor-controller side of the UDP transport. Setup (create) binds HOST:PORT
// and may allocate; afterwards poll()/wait() are noexcept and allocation-free: each
// datagram is received into a fixed buffer, fully validated by decode_datagram, then
// accepted only if its sequence number is newer than the last accepted one (a jump of
// more than 1 adds the missing frames to `dropped_frames`). Stale or duplicate sequence
// numbers are dropped, except when the capture time moved forward (tracker restarted:
// sequence restarts, `restarts` is counted). Every rejection is a counter, never a log.
// Multicast: when HOST is a multicast group (224.0.0.0/4) the socket binds the group's
// port with SO_REUSEADDR (several consumers may listen to one group) and joins the group
// (IP_ADD_MEMBERSHIP) on `multicast_interface` (an IPv4 address of a local interface;
// empty: the kernel's choice by route, which fails on a host without a multicast route,
// e.g. use "127.0.0.1" to receive a tracker on the same machine over loopback).
// Not thread-safe: one thread owns a receiver.
#pragma once

#include <array>
#include <chrono>
#include <cstdint>
#include <string>

#include "client/datagram.h"
#include "client/joints_message.h"
#include "core/expected.h"

namespace mocap::client {

struct ReceiverCounters {
  std::uint64_t datagrams = 0;                               // datagrams read from the socket
  std::uint64_t accepted = 0;                                // valid and newer: became latest()
  std::array<std::uint64_t, kDecodeStatusCount> rejected{};  // by DecodeStatus (kOk unused)
  std::uint64_t oversized = 0;       // longer than the largest v1 datagram (also kBadLength)
  std::uint64_t stale = 0;           // valid but sequence not newer (reordered/duplicate)
  std::uint64_t dropped_frames = 0;  // sum of sequence gaps between accepted messages
  std::uint64_t restarts = 0;        // sequence went back with a newer capture time
  std::uint64_t socket_errors = 0;   // recv/poll errors other than "no data"

  std::uint64_t rejected_total() const noexcept;
  std::uint64_t rejected_for(DecodeStatus s) const noexcept {
    return rejected[static_cast<std::size_t>(s)];
  }
};

class UdpReceiver {
 public:
  // Binds "HOST:PORT" (e.g. "127.0.0.1:9870"; port 0 = ephemeral, see port()), or joins
  // the multicast group HOST (see above).
  static Expected<UdpReceiver> create(const std::string& bind_host_port,
                                      const std::string& multicast_interface = "");
  bool multicast() const noexcept { return multicast_; }

  UdpReceiver(UdpReceiver&& other) noexcept;
  UdpReceiver& operator=(UdpReceiver&& other) noexcept;
  UdpReceiver(const UdpReceiver&) = delete;
  UdpReceiver& operator=(const UdpReceiver&) = delete;
  ~UdpReceiver();

  std::uint16_t port() const noexcept { return port_; }

  // Reads every pending datagram without blocking; returns how many were accepted.
  int poll() noexcept;
  // Waits up to `timeout` for data, then behaves like poll().
  int wait(std::chrono::microseconds timeout) noexcept;

  bool has_message() const noexcept { return counters_.accepted > 0; }
  const JointsMessage& latest() const noexcept { return latest_; }
  // The datagram version of latest() (1: its quality and rates are defaults; 2: carried).
  std::uint16_t latest_version() const noexcept { return latest_version_; }
  const ReceiverCounters& counters() const noexcept { return counters_; }

 private:
  UdpReceiver(int fd, std::uint16_t port, bool multicast) noexcept
      : fd_(fd), port_(port), multicast_(multicast) {}
  void handle(std::size_t len) noexcept;

  int fd_ = -1;
  std::uint16_t port_ = 0;
  bool multicast_ = false;
  ReceiverCounters counters_{};
  JointsMessage latest_{};
  JointsMessage scratch_{};
  std::uint16_t latest_version_ = 0, scratch_version_ = 0;
  std::array<std::uint8_t, kMaxDatagramBytes + 1> buf_{};
};

}  // namespace mocap::client
