// Design: the VRPN server's sockets. Single-threaded: every call but counters() and
// port() comes from ONE thread (the VRPN sink's worker, never the real-time publish
// thread), so the client slots need no locks; the counters are relaxed atomics read by
// other threads as statistics. Sockets are non-blocking and serviced by poll() with a
// zero timeout; nothing here ever waits on a client.
//   - TCP listener and UDP socket on the same ADDRESS:PORT (default 127.0.0.1:3883);
//   - a direct TCP connection is accepted; a UDP connection request ("HOST PORT") makes
//     the server connect back over TCP to the datagram's SOURCE address at PORT;
//   - at most max_clients clients (pending connect-backs included); one more is closed
//     at once (TCP) or ignored (UDP request) and counted (clients_refused);
//   - on connecting, the server sends its cookie, one sender description per body and
//     the type descriptions; reports go only to clients whose cookie arrived;
//   - each client has a preallocated output buffer (client_buffer_bytes; its socket's
//     kernel send buffer is set to about as much): a frame's
//     reports that do not fit are dropped for that client (frames_dropped); a client
//     whose pending bytes make no progress for stall_ms is disconnected (stalled);
//   - a client that asked for UDP data (UDP description) gets the reports by UDP
//     datagrams (<= 1472 bytes) from the server's UDP socket to its TCP peer address;
//     a full socket buffer drops that datagram (frames_dropped);
//   - incoming bytes: at most kInputBytes buffered per client and max_input_bytes_per_s
//     per client (more: disconnected, flooding); the session (vrpn_session.h) parses
//     them; a protocol violation or no cookie within handshake_ms disconnects
//     (protocol_errors).
// Implementation: vrpn_server.cpp (the listening side and the poll loop), vrpn_client.cpp
// (one client's connection), their shared state in vrpn_server_impl.h.
#pragma once

#include <atomic>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "core/expected.h"
#include "pipeline/publish/frame_result.h"

namespace mocap::publish::vrpn {

struct ServerOptions {
  std::string address = "127.0.0.1";  // IPv4 (VRPN's sockets are IPv4)
  std::uint16_t port = 3883;          // 0: any free port (tests), see port()
  int max_clients = 8;
  std::size_t client_buffer_bytes = 64 * 1024;  // pending output per client
  int stall_ms = 2000;
  int handshake_ms = 5000;
  std::size_t max_input_bytes_per_s = 64 * 1024;
  double frame_period_s = 0.01;  // vel_quat_dt of Velocity reports
};

struct ServerCounters {
  std::uint64_t clients_accepted = 0;  // TCP connections accepted (direct)
  std::uint64_t connect_backs = 0;     // TCP connections opened for a UDP request
  std::uint64_t connect_failures = 0;  // connect-backs that failed or timed out
  std::uint64_t clients_refused = 0;   // beyond max_clients
  std::uint64_t bad_requests = 0;      // malformed UDP connection requests
  std::uint64_t protocol_errors = 0;   // sessions closed for a violation / no cookie
  std::uint64_t flooding = 0;          // sessions closed for sending too much
  std::uint64_t stalled = 0;           // sessions closed because writes made no progress
  std::uint64_t frames_dropped = 0;    // a frame's reports not sent to one client
  std::uint64_t reports_sent = 0;      // Pos_Quat + Velocity messages handed to sockets
  std::uint64_t pongs_sent = 0;
  int clients_active = 0;  // sessions whose cookie arrived
};

class Server {
 public:
  // Binds both sockets (one-line errors: "ADDRESS:PORT: cannot listen: ..."); `bodies`
  // are the tracker names (sender ids = indices).
  static Expected<std::unique_ptr<Server>> create(const ServerOptions& options,
                                                  std::vector<std::string> bodies);
  ~Server();
  Server(const Server&) = delete;
  Server& operator=(const Server&) = delete;

  // Owner thread: accept, connection requests, connect-backs, reads, flushes, timeouts.
  void poll(std::int64_t now_ns) noexcept;
  // Owner thread: the frame's reports to every client (the frame's capture time on the
  // system clock = capture_ns + realtime_offset_ns).
  void send_frame(const FrameResult& frame, std::int64_t realtime_offset_ns,
                  std::int64_t now_ns) noexcept;

  std::uint16_t port() const noexcept { return port_; }
  ServerCounters counters() const noexcept;

  struct Impl;

 private:
  Server() = default;
  std::unique_ptr<Impl> impl_;
  std::uint16_t port_ = 0;
};

// "[ADDRESS:]PORT" -> options.address / options.port (IPv4 dotted address, PORT
// 0..65535); one-line error naming `key`.
Expected<void> parse_listen_address(const std::string& text, const std::string& key,
                                    ServerOptions& options);

}  // namespace mocap::publish::vrpn
