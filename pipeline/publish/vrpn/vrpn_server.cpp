// Design: see vrpn_server.h; the server's listening side (the state it shares with one
// client's connection, vrpn_client.cpp, is in vrpn_server_impl.h). The client slots, their
// output buffers and the poll set are allocated in create(); poll() and send_frame()
// allocate nothing. Connection handling follows
// vrpn_Connection_IP::server_check_for_incoming_connections (TCP accept, UDP request then
// connect back).
#include "pipeline/publish/vrpn/vrpn_server.h"

#include <arpa/inet.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>

#include <algorithm>
#include <cerrno>
#include <iterator>

#include "pipeline/publish/vrpn/vrpn_listen.h"
#include "pipeline/publish/vrpn/vrpn_reports.h"
#include "pipeline/publish/vrpn/vrpn_server_impl.h"
#include "pipeline/publish/vrpn/vrpn_wire.h"

namespace mocap::publish::vrpn {

VrpnClient* Server::Impl::free_slot() noexcept {
  for (VrpnClient& c : clients)
    if (c.state == VrpnClient::State::kFree) return &c;
  return nullptr;
}

void Server::Impl::accept_tcp(std::int64_t now) noexcept {
  for (int k = 0; k < kBurst; ++k) {
    sockaddr_in from{};
    socklen_t len = sizeof from;
    const int fd =
        ::accept4(tcp, reinterpret_cast<sockaddr*>(&from), &len, SOCK_NONBLOCK | SOCK_CLOEXEC);
    if (fd < 0) return;  // EAGAIN, or EMFILE & co.: tried again on the next poll
    VrpnClient* c = free_slot();
    if (c == nullptr) {
      ::close(fd);
      add(counters.refused);
      continue;
    }
    c->fd = fd;
    c->peer = from;
    add(counters.accepted);
    open_session(*c, now);
  }
}

void Server::Impl::take_requests(std::int64_t now) noexcept {
  for (int k = 0; k < kBurst; ++k) {
    std::uint8_t msg[256];
    sockaddr_in from{};
    socklen_t len = sizeof from;
    const ssize_t r =
        ::recvfrom(udp, msg, sizeof msg, MSG_DONTWAIT, reinterpret_cast<sockaddr*>(&from), &len);
    if (r < 0) return;
    std::uint16_t port = 0;
    if (from.sin_family != AF_INET ||
        !parse_connection_request(msg, static_cast<std::size_t>(r), port)) {
      add(counters.bad_requests);
      continue;
    }
    // A client lobs its request every 2 s until connected: one connection per request.
    bool known = false;
    for (const VrpnClient& c : clients)
      known = known || (c.state != VrpnClient::State::kFree && c.connect_port == port &&
                        c.peer.sin_addr.s_addr == from.sin_addr.s_addr);
    if (known) continue;
    VrpnClient* c = free_slot();
    if (c == nullptr) {
      add(counters.refused);
      continue;
    }
    c->fd = ::socket(AF_INET, SOCK_STREAM | SOCK_NONBLOCK | SOCK_CLOEXEC, 0);
    if (c->fd < 0) {
      add(counters.connect_failures);
      continue;
    }
    c->peer = from;
    c->peer.sin_port = htons(port);  // the SOURCE address, the requested port
    c->connect_port = port;
    add(counters.connect_backs);
    if (::connect(c->fd, reinterpret_cast<const sockaddr*>(&c->peer), sizeof c->peer) == 0) {
      open_session(*c, now);
    } else if (errno == EINPROGRESS) {
      c->state = VrpnClient::State::kConnecting;
      c->opened_ns = now;
    } else {
      add(counters.connect_failures);
      close_client(*c);
    }
  }
}

Expected<std::unique_ptr<Server>> Server::create(const ServerOptions& options,
                                                 std::vector<std::string> bodies) {
  if (options.max_clients < 1 || options.stall_ms < 1 || options.handshake_ms < 1 ||
      options.max_input_bytes_per_s < kInputBytes || !(options.frame_period_s > 0.0))
    return make_error("vrpn", "", "limits must be positive");
  // The descriptions sent on connecting must fit a client's buffer with room for frames.
  const std::size_t hello =
      kCookieBytes + (bodies.size() + std::size(kOurTypes)) * message_bytes(4 + kMaxNameBytes);
  if (options.client_buffer_bytes < hello + bodies.size() * kReportBytes)
    return make_error("vrpn", "",
                      "client buffer too small for " + std::to_string(bodies.size()) + " bodies");
  for (const std::string& b : bodies)
    if (b.empty() || b.size() > kMaxNameChars)
      return make_error(
          "vrpn", "'" + b + "'",
          "a VRPN sender name has 1.." + std::to_string(kMaxNameChars) + " characters");
  auto sockets = open_listen_sockets(options);
  if (!sockets) return sockets.error();
  auto impl = std::make_unique<Impl>();
  impl->options = options;
  impl->bodies = std::move(bodies);
  impl->tcp = sockets->tcp;
  impl->udp = sockets->udp;
  impl->clients.reserve(static_cast<std::size_t>(options.max_clients));
  for (int i = 0; i < options.max_clients; ++i)
    impl->clients.emplace_back(&impl->bodies, options.client_buffer_bytes);
  impl->fds.reserve(impl->clients.size() + 2);
  impl->fd_client.reserve(impl->clients.size() + 2);
  impl->frame.resize(std::max<std::size_t>(impl->bodies.size(), 1) * kReportBytes);
  std::unique_ptr<Server> server(new Server());
  server->impl_ = std::move(impl);
  server->port_ = sockets->port;
  return server;
}

Server::~Server() {
  if (!impl_) return;
  for (VrpnClient& c : impl_->clients) close_fd(c.fd);
  close_fd(impl_->tcp);
  close_fd(impl_->udp);
}

void Server::poll(std::int64_t now_ns) noexcept {
  Impl& s = *impl_;
  s.fds.clear();  // capacity reserved in create(): no allocation
  s.fd_client.clear();
  s.fds.push_back({s.tcp, POLLIN, 0});
  s.fd_client.push_back(-1);
  s.fds.push_back({s.udp, POLLIN, 0});
  s.fd_client.push_back(-1);
  for (std::size_t i = 0; i < s.clients.size(); ++i) {
    const VrpnClient& c = s.clients[i];
    if (c.state == VrpnClient::State::kFree) continue;
    short events = c.state == VrpnClient::State::kConnecting ? POLLOUT : POLLIN;
    if (c.out_begin < c.out_end) events = static_cast<short>(events | POLLOUT);
    s.fds.push_back({c.fd, events, 0});
    s.fd_client.push_back(static_cast<int>(i));
  }
  if (::poll(s.fds.data(), s.fds.size(), 0) < 0) return;
  for (std::size_t k = 2; k < s.fds.size(); ++k) {
    VrpnClient& c = s.clients[static_cast<std::size_t>(s.fd_client[k])];
    const short ev = s.fds[k].revents;
    if (ev == 0) continue;
    if (c.state == VrpnClient::State::kConnecting) {
      int err = 0;
      socklen_t len = sizeof err;
      if (::getsockopt(c.fd, SOL_SOCKET, SO_ERROR, &err, &len) == 0 && err == 0 &&
          (ev & POLLOUT) != 0) {
        s.open_session(c, now_ns);
      } else {
        Impl::add(s.counters.connect_failures);
        s.close_client(c);
      }
      continue;
    }
    if ((ev & (POLLIN | POLLHUP | POLLERR)) != 0) s.read_client(c, now_ns);
    if (c.state == VrpnClient::State::kOpen && (ev & POLLOUT) != 0) s.flush(c, now_ns);
  }
  if ((s.fds[0].revents & POLLIN) != 0) s.accept_tcp(now_ns);
  if ((s.fds[1].revents & POLLIN) != 0) s.take_requests(now_ns);
  // Deadlines: connect-back and cookie within handshake_ms, write progress within stall_ms.
  const std::int64_t handshake_ns = std::int64_t{s.options.handshake_ms} * 1'000'000;
  const std::int64_t stall_ns = std::int64_t{s.options.stall_ms} * 1'000'000;
  int active = 0;
  for (VrpnClient& c : s.clients) {
    if (c.state == VrpnClient::State::kConnecting && now_ns - c.opened_ns > handshake_ns) {
      Impl::add(s.counters.connect_failures);
      s.close_client(c);
    } else if (c.state == VrpnClient::State::kOpen && !c.session.cookie_received() &&
               now_ns - c.opened_ns > handshake_ns) {
      Impl::add(s.counters.protocol_errors);
      s.close_client(c);
    } else if (c.state == VrpnClient::State::kOpen && c.out_begin < c.out_end &&
               now_ns - c.last_progress_ns > stall_ns) {
      Impl::add(s.counters.stalled);
      s.close_client(c);
    }
    active += c.state == VrpnClient::State::kOpen && c.session.cookie_received() ? 1 : 0;
  }
  s.counters.active.store(active, std::memory_order_relaxed);
}

void Server::send_frame(const FrameResult& f, std::int64_t realtime_offset_ns,
                        std::int64_t now_ns) noexcept {
  Impl& s = *impl_;
  if (s.counters.active.load(std::memory_order_relaxed) == 0) return;
  const WireTime t = wire_time(f.joints.capture_ns + realtime_offset_ns);
  const std::size_t n_bodies = std::min<std::size_t>(
      {s.bodies.size(), static_cast<std::size_t>(std::max(f.body_count, 0)), f.bodies.size()});
  std::uint64_t reports = 0;
  const std::size_t bytes =
      encode_frame_reports(f, n_bodies, s.options.frame_period_s, t, s.sequence, s.frame.data(),
                           s.frame.size(), reports);
  if (bytes == 0) return;
  for (VrpnClient& c : s.clients) {
    if (c.state != VrpnClient::State::kOpen || !c.session.cookie_received()) continue;
    if (c.udp_port != 0) {
      s.send_udp(c, bytes);
    } else if (!s.append(c, s.frame.data(), bytes, now_ns)) {
      Impl::add(s.counters.frames_dropped);
      continue;
    } else {
      s.flush(c, now_ns);
    }
    Impl::add(s.counters.reports_sent, reports);
  }
}

ServerCounters Server::counters() const noexcept {
  const auto& c = impl_->counters;
  auto get = [](const std::atomic<std::uint64_t>& a) { return a.load(std::memory_order_relaxed); };
  ServerCounters out;
  out.clients_accepted = get(c.accepted);
  out.connect_backs = get(c.connect_backs);
  out.connect_failures = get(c.connect_failures);
  out.clients_refused = get(c.refused);
  out.bad_requests = get(c.bad_requests);
  out.protocol_errors = get(c.protocol_errors);
  out.flooding = get(c.flooding);
  out.stalled = get(c.stalled);
  out.frames_dropped = get(c.frames_dropped);
  out.reports_sent = get(c.reports_sent);
  out.pongs_sent = get(c.pongs_sent);
  out.clients_active = c.active.load(std::memory_order_relaxed);
  return out;
}

}  // namespace mocap::publish::vrpn
