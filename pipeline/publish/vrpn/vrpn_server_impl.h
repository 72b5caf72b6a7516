// Design: the state of the VRPN server (vrpn_server.h) shared by its two halves, private
// to them: the listening side (vrpn_server.cpp: create(), the poll loop with its accepts,
// connection requests and connect-backs, the deadlines, a frame to every client, the
// counters) and one client's connection (vrpn_client.cpp: its output buffer and flushes,
// the handshake, its input and pongs, its UDP reports). Everything here is touched from
// the owner thread only, but the counters (relaxed atomics, statistics).
#pragma once

#include <netinet/in.h>
#include <poll.h>
#include <unistd.h>

#include <atomic>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "pipeline/publish/vrpn/vrpn_server.h"
#include "pipeline/publish/vrpn/vrpn_session.h"

namespace mocap::publish::vrpn {

// Accepts / requests / reads per poll() and socket.
inline constexpr int kBurst = 16;

inline void close_fd(int& fd) noexcept {
  if (fd >= 0) ::close(fd);
  fd = -1;
}

struct VrpnClient {
  enum class State { kFree, kConnecting, kOpen };
  explicit VrpnClient(const std::vector<std::string>* bodies, std::size_t buffer_bytes)
      : out(buffer_bytes), session(bodies) {}
  State state = State::kFree;
  int fd = -1;
  sockaddr_in peer{};
  std::uint16_t connect_port = 0;  // connect-back: the requested TCP port
  std::uint16_t udp_port = 0;      // nonzero: reports by UDP
  std::vector<std::uint8_t> out;   // [out_begin, out_end) pending
  std::size_t out_begin = 0, out_end = 0;
  Session session;
  std::int64_t opened_ns = 0, last_progress_ns = 0, window_start_ns = 0;
  std::size_t window_bytes = 0;
};

struct Server::Impl {
  ServerOptions options;
  std::vector<std::string> bodies;
  int tcp = -1, udp = -1;
  std::vector<VrpnClient> clients;
  std::vector<pollfd> fds;
  std::vector<int> fd_client;       // fds[i] -> client index (-1: a listener)
  std::vector<std::uint8_t> frame;  // one frame's reports
  std::uint32_t sequence = 0;
  struct {
    std::atomic<std::uint64_t> accepted{0}, connect_backs{0}, connect_failures{0}, refused{0},
        bad_requests{0}, protocol_errors{0}, flooding{0}, stalled{0}, frames_dropped{0},
        reports_sent{0}, pongs_sent{0};
    std::atomic<int> active{0};
  } counters;

  static void add(std::atomic<std::uint64_t>& c, std::uint64_t n = 1) noexcept {
    c.fetch_add(n, std::memory_order_relaxed);  // statistics only
  }
  // The first free client slot, or nullptr.
  VrpnClient* free_slot() noexcept;

  // One client's connection (vrpn_client.cpp).
  void close_client(VrpnClient& c) noexcept;
  // Appends n bytes to c's pending output (compacting it first when needed); false: no
  // room (nothing appended).
  bool append(VrpnClient& c, const std::uint8_t* data, std::size_t n, std::int64_t now) noexcept;
  // Sends what c's socket takes now; closes c on a socket error.
  void flush(VrpnClient& c, std::int64_t now) noexcept;
  // c's socket is connected: the cookie and the descriptions.
  void open_session(VrpnClient& c, std::int64_t now) noexcept;
  // c's incoming bytes: flood limit, the session's messages, pongs.
  void read_client(VrpnClient& c, std::int64_t now) noexcept;
  // The frame's first `bytes` of reports to c by UDP datagrams.
  void send_udp(VrpnClient& c, std::size_t bytes) noexcept;

  // The listening side (vrpn_server.cpp).
  void accept_tcp(std::int64_t now) noexcept;
  void take_requests(std::int64_t now) noexcept;
};

}  // namespace mocap::publish::vrpn
