// Design: one client connection of the VRPN server (vrpn_server_impl.h), after
// vrpn_Endpoint_IP::setup_new_connection / finish_new_connection_setup: on connecting the
// cookie, one sender description per body and the type descriptions; the pending output
// in the client's preallocated buffer, flushed without waiting (what the socket does not
// take stays pending, the stall clock runs while nothing moves); the incoming bytes under
// the per-second flood limit into the client's Session (vrpn_session.h), answered by pongs;
// a client that asked for UDP gets the frame's reports as datagrams of whole messages.
// The server's poll loop (vrpn_server.cpp) decides when each runs; nothing here allocates
// or waits.
#include <netinet/tcp.h>
#include <sys/socket.h>
#include <time.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <iterator>

#include "pipeline/publish/vrpn/vrpn_reports.h"
#include "pipeline/publish/vrpn/vrpn_server_impl.h"
#include "pipeline/publish/vrpn/vrpn_wire.h"

namespace mocap::publish::vrpn {

namespace {

std::int64_t realtime_now_ns() noexcept {
  timespec ts{};
  ::clock_gettime(CLOCK_REALTIME, &ts);
  return std::int64_t{ts.tv_sec} * 1'000'000'000 + ts.tv_nsec;
}

}  // namespace

void Server::Impl::close_client(VrpnClient& c) noexcept {
  close_fd(c.fd);
  c.state = VrpnClient::State::kFree;
  c.udp_port = 0;
  c.connect_port = 0;
  c.out_begin = c.out_end = 0;
}

bool Server::Impl::append(VrpnClient& c, const std::uint8_t* data, std::size_t n,
                          std::int64_t now) noexcept {
  if (c.out.size() - c.out_end < n && c.out_begin > 0) {  // compact
    std::memmove(c.out.data(), c.out.data() + c.out_begin, c.out_end - c.out_begin);
    c.out_end -= c.out_begin;
    c.out_begin = 0;
  }
  if (c.out.size() - c.out_end < n) return false;
  if (c.out_begin == c.out_end) c.last_progress_ns = now;  // the stall clock starts
  std::memcpy(c.out.data() + c.out_end, data, n);
  c.out_end += n;
  return true;
}

void Server::Impl::flush(VrpnClient& c, std::int64_t now) noexcept {
  while (c.out_begin < c.out_end) {
    const ssize_t r = ::send(c.fd, c.out.data() + c.out_begin, c.out_end - c.out_begin,
                             MSG_DONTWAIT | MSG_NOSIGNAL);
    if (r < 0 && errno == EINTR) continue;
    if (r < 0 && (errno == EAGAIN || errno == EWOULDBLOCK)) return;
    if (r <= 0) return close_client(c);
    c.out_begin += static_cast<std::size_t>(r);
    c.last_progress_ns = now;
  }
  c.out_begin = c.out_end = 0;
}

void Server::Impl::open_session(VrpnClient& c, std::int64_t now) noexcept {
  c.state = VrpnClient::State::kOpen;
  c.session.reset();
  c.opened_ns = c.window_start_ns = now;
  c.window_bytes = 0;
  const int one = 1;
  ::setsockopt(c.fd, IPPROTO_TCP, TCP_NODELAY, &one, sizeof one);  // best effort
  // The kernel's share of a slow client's backlog bounded too (no autotuning to MBs of
  // reports seconds old): about client_buffer_bytes (the kernel doubles the value).
  const int sndbuf =
      static_cast<int>(std::min<std::size_t>(options.client_buffer_bytes / 2, 1 << 24));
  ::setsockopt(c.fd, SOL_SOCKET, SO_SNDBUF, &sndbuf, sizeof sndbuf);
  std::uint8_t buf[kCookieBytes + message_bytes(4 + kMaxNameBytes)];
  write_cookie(buf);
  (void)append(c, buf, kCookieBytes, now);
  const WireTime t = wire_time(realtime_now_ns());
  std::uint8_t name[4 + kMaxNameBytes];
  for (std::size_t i = 0; i < bodies.size() + std::size(kOurTypes); ++i) {
    const bool sender = i < bodies.size();
    const std::size_t id = sender ? i : i - bodies.size();
    const std::size_t len =
        write_name_payload(name, sizeof name, sender ? bodies[id] : kOurTypes[id]);
    const std::size_t n =
        write_message(buf, sizeof buf, sender ? kSenderDescription : kTypeDescription,
                      static_cast<std::int32_t>(id), t, sequence++, name, len);
    if (!append(c, buf, n, now)) return close_client(c);  // buffer >= all (create())
  }
  flush(c, now);
}

void Server::Impl::read_client(VrpnClient& c, std::int64_t now) noexcept {
  if (now - c.window_start_ns >= 1'000'000'000) {
    c.window_start_ns = now;
    c.window_bytes = 0;
  }
  for (int k = 0; k < kBurst && c.state == VrpnClient::State::kOpen; ++k) {
    const std::size_t room = c.session.space_bytes();
    if (room == 0) break;  // cannot happen: process() always frees complete messages
    const ssize_t r = ::recv(c.fd, c.session.space(), room, MSG_DONTWAIT);
    if (r < 0 && errno == EINTR) continue;
    if (r < 0 && (errno == EAGAIN || errno == EWOULDBLOCK)) return;
    if (r <= 0) return close_client(c);  // closed by the client or a socket error
    c.session.commit(static_cast<std::size_t>(r));
    c.window_bytes += static_cast<std::size_t>(r);
    if (c.window_bytes > options.max_input_bytes_per_s) {
      add(counters.flooding);
      return close_client(c);
    }
    SessionActions actions;
    if (!c.session.process(actions)) {
      add(counters.protocol_errors);
      return close_client(c);
    }
    if (actions.udp_port != 0) c.udp_port = actions.udp_port;
    const WireTime t = wire_time(realtime_now_ns());
    for (int i = 0; i < actions.pong_count; ++i) {
      std::uint8_t msg[kHeaderBytes];
      const std::size_t n =
          write_message(msg, sizeof msg, kTypePong, actions.pongs[static_cast<std::size_t>(i)], t,
                        sequence++, nullptr, 0);
      if (append(c, msg, n, now)) add(counters.pongs_sent);
    }
    if (actions.pong_count > 0) flush(c, now);
  }
}

void Server::Impl::send_udp(VrpnClient& c, std::size_t bytes) noexcept {
  sockaddr_in to = c.peer;
  to.sin_port = htons(c.udp_port);
  std::size_t at = 0;
  bool dropped = false;
  while (at < bytes) {  // whole messages, at most kUdpPayloadBytes per datagram
    std::size_t end = at;
    while (end < bytes) {
      const std::size_t m = padded(get_u32(frame.data() + end));
      if (end + m - at > kUdpPayloadBytes) break;
      end += m;
    }
    if (::sendto(udp, frame.data() + at, end - at, MSG_DONTWAIT,
                 reinterpret_cast<const sockaddr*>(&to), sizeof to) < 0)
      dropped = true;
    at = end;
  }
  if (dropped) add(counters.frames_dropped);
}

}  // namespace mocap::publish::vrpn
