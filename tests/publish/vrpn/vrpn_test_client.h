// Design: a VRPN client for the tests, written from VRPN's protocol (vrpn_Connection.C,
// vrpn_Tracker.C) independently of pipeline/publish/vrpn: it shares no code with the
// server (its own big-endian reading, cookie, framing and report decoding), so that an
// encoding mistake of the server cannot cancel out. It connects either directly over
// TCP or the way vrpn_mocap and libmotioncapture do by default (a TCP listener of its
// own, "HOST PORT" lobbed by UDP to the server's port, the server connects back). It
// keeps the server's sender/type descriptions and decodes every Pos_Quat and Velocity
// report, counting anything malformed as a protocol error. Blocking with timeouts;
// single-threaded; test code only.
#pragma once

#include <arpa/inet.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <cstring>
#include <functional>
#include <map>
#include <string>
#include <vector>

namespace mocap::test::vrpn_client {

inline std::uint32_t be32(const std::uint8_t* p) {
  return (std::uint32_t(p[0]) << 24) | (std::uint32_t(p[1]) << 16) | (std::uint32_t(p[2]) << 8) |
         std::uint32_t(p[3]);
}
inline double be64f(const std::uint8_t* p) {
  std::uint64_t u = 0;
  for (int i = 0; i < 8; ++i) u = (u << 8) | p[i];
  double d;
  std::memcpy(&d, &u, 8);
  return d;
}
inline void put_be32(std::vector<std::uint8_t>& v, std::uint32_t x) {
  for (int s = 24; s >= 0; s -= 8) v.push_back(static_cast<std::uint8_t>(x >> s));
}

struct Report {
  std::string body;  // the sender's described name
  std::string type;  // the type's described name
  std::int32_t sec = 0, usec = 0;
  std::int32_t sensor = -1;
  double pos[3] = {0, 0, 0}, quat[4] = {0, 0, 0, 0};              // Pos_Quat
  double vel[3] = {0, 0, 0}, vel_quat[4] = {0, 0, 0, 0}, dt = 0;  // Velocity
  bool via_udp = false;
};

class Client {
 public:
  ~Client() {
    for (int fd : {tcp_, listen_, udp_in_})
      if (fd >= 0) ::close(fd);
  }
  // Direct TCP to 127.0.0.1:port.
  bool connect_tcp(std::uint16_t port) {
    if (tcp_ >= 0) ::close(tcp_);
    tcp_ = ::socket(AF_INET, SOCK_STREAM, 0);
    sockaddr_in a = loopback(port);
    return ::connect(tcp_, reinterpret_cast<sockaddr*>(&a), sizeof a) == 0;
  }
  // The UDP connection request: listen, lob "127.0.0.1 PORT\0", accept the server's call.
  bool request_connect_back(std::uint16_t server_port, int timeout_ms = 3000) {
    listen_ = ::socket(AF_INET, SOCK_STREAM, 0);
    sockaddr_in a = loopback(0);
    socklen_t len = sizeof a;
    if (::bind(listen_, reinterpret_cast<sockaddr*>(&a), sizeof a) != 0 ||
        ::listen(listen_, 1) != 0)
      return false;
    ::getsockname(listen_, reinterpret_cast<sockaddr*>(&a), &len);
    listen_port_ = ntohs(a.sin_port);
    const std::string msg = "127.0.0.1 " + std::to_string(listen_port_);
    send_datagram(server_port, msg.c_str(), msg.size() + 1);
    pollfd p{listen_, POLLIN, 0};
    const auto t0 = std::chrono::steady_clock::now();
    while (::poll(&p, 1, 10) == 0) {
      if (on_wait) on_wait();  // lets a single-threaded test drive the server
      if (std::chrono::steady_clock::now() - t0 > std::chrono::milliseconds(timeout_ms))
        return false;
    }
    tcp_ = ::accept(listen_, nullptr, nullptr);
    return tcp_ >= 0;
  }
  void send_datagram(std::uint16_t port, const void* data, std::size_t n) const {
    const int s = ::socket(AF_INET, SOCK_DGRAM, 0);
    sockaddr_in a = loopback(port);
    ::sendto(s, data, n, 0, reinterpret_cast<sockaddr*>(&a), sizeof a);
    ::close(s);
  }
  // Our cookie: "vrpn: ver. 07.MM", two spaces, log mode '0', NULs up to 24 bytes.
  void send_cookie(const char* magic = "vrpn: ver. 07.35") {
    std::vector<std::uint8_t> c(24, 0);
    std::memcpy(c.data(), magic, std::min<std::size_t>(16, std::strlen(magic)));
    c[16] = c[17] = ' ';
    c[18] = '0';
    send_raw(c);
  }
  void send_raw(const std::vector<std::uint8_t>& b) const {
    ::send(tcp_, b.data(), b.size(), MSG_NOSIGNAL | MSG_DONTWAIT);  // never blocks the test
  }
  static std::vector<std::uint8_t> message(std::int32_t type, std::int32_t sender,
                                           const std::vector<std::uint8_t>& payload) {
    std::vector<std::uint8_t> m;
    put_be32(m, static_cast<std::uint32_t>(24 + payload.size()));
    put_be32(m, 0);
    put_be32(m, 0);
    put_be32(m, static_cast<std::uint32_t>(sender));
    put_be32(m, static_cast<std::uint32_t>(type));
    put_be32(m, 0);
    m.insert(m.end(), payload.begin(), payload.end());
    while (m.size() % 8 != 0) m.push_back(0);
    return m;
  }
  static std::vector<std::uint8_t> name_payload(const std::string& name) {
    std::vector<std::uint8_t> p;
    put_be32(p, static_cast<std::uint32_t>(name.size() + 1));
    p.insert(p.end(), name.begin(), name.end());
    p.push_back(0);
    return p;
  }
  // Asks for UDP reports (vrpn_CONNECTION_UDP_DESCRIPTION, sender field = our UDP port).
  bool ask_udp() {
    udp_in_ = ::socket(AF_INET, SOCK_DGRAM, 0);
    sockaddr_in a = loopback(0);
    socklen_t len = sizeof a;
    const int rcvbuf = 1 << 20;  // seconds of reports while the test thread is busy
    ::setsockopt(udp_in_, SOL_SOCKET, SO_RCVBUF, &rcvbuf, sizeof rcvbuf);
    if (::bind(udp_in_, reinterpret_cast<sockaddr*>(&a), sizeof a) != 0) return false;
    ::getsockname(udp_in_, reinterpret_cast<sockaddr*>(&a), &len);
    const std::string host = "127.0.0.1";
    std::vector<std::uint8_t> p(host.begin(), host.end());
    p.push_back(0);
    send_raw(message(-3, ntohs(a.sin_port), p));
    return true;
  }

  // Reads what arrives within timeout_ms (TCP and UDP); false when the server closed.
  bool pump(int timeout_ms) {
    const auto end = std::chrono::steady_clock::now() + std::chrono::milliseconds(timeout_ms);
    while (true) {
      if (on_wait) on_wait();
      pollfd p[2] = {{tcp_, POLLIN, 0}, {udp_in_, POLLIN, 0}};
      const int n = ::poll(p, udp_in_ >= 0 ? 2 : 1, 5);
      if (n > 0 && (p[0].revents & (POLLIN | POLLHUP | POLLERR)) != 0) {
        std::uint8_t buf[65536];
        const ssize_t r = ::recv(tcp_, buf, sizeof buf, 0);
        if (r <= 0) return false;
        in_.insert(in_.end(), buf, buf + r);
        parse_stream();
      }
      if (n > 0 && udp_in_ >= 0 && (p[1].revents & POLLIN) != 0) {
        std::uint8_t buf[2048];  // every datagram waiting: a slow test loop loses none
        for (ssize_t r; (r = ::recv(udp_in_, buf, sizeof buf, MSG_DONTWAIT)) > 0;)
          parse_messages(buf, static_cast<std::size_t>(r), true);
      }
      if (std::chrono::steady_clock::now() >= end) return true;
    }
  }

  std::function<void()> on_wait;  // called while waiting (drive a same-thread server)
  bool cookie_ok = false;
  std::string server_cookie;
  std::map<std::int32_t, std::string> senders, types;
  std::vector<Report> reports;
  std::vector<std::pair<std::string, std::string>> others;  // (sender, type) of the rest
  int protocol_errors = 0;
  int fd() const { return tcp_; }
  std::uint16_t listen_port() const { return listen_port_; }  // of request_connect_back

 private:
  static sockaddr_in loopback(std::uint16_t port) {
    sockaddr_in a{};
    a.sin_family = AF_INET;
    a.sin_port = htons(port);
    a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    return a;
  }
  void parse_stream() {
    if (!cookie_ok) {
      if (in_.size() < 24) return;
      server_cookie.assign(reinterpret_cast<const char*>(in_.data()), 16);
      cookie_ok = server_cookie.rfind("vrpn: ver. 07.", 0) == 0 && in_[18] == '0';
      if (!cookie_ok) ++protocol_errors;
      in_.erase(in_.begin(), in_.begin() + 24);
    }
    const std::size_t used = parse_messages(in_.data(), in_.size(), false);
    in_.erase(in_.begin(), in_.begin() + static_cast<std::ptrdiff_t>(used));
  }
  std::size_t parse_messages(const std::uint8_t* p, std::size_t n, bool udp) {
    std::size_t at = 0;
    while (n - at >= 24) {
      const std::uint32_t len = be32(p + at);
      if (len < 24 || len > 64000) {
        ++protocol_errors;
        return n;
      }
      const std::size_t total = (len + 7) / 8 * 8;
      if (n - at < total) break;
      handle(p + at, len - 24, udp);
      at += total;
    }
    if (udp && at != n) ++protocol_errors;  // a datagram holds whole messages
    return at;
  }
  void handle(const std::uint8_t* m, std::size_t payload_len, bool udp) {
    const auto sender = static_cast<std::int32_t>(be32(m + 12));
    const auto type = static_cast<std::int32_t>(be32(m + 16));
    const std::uint8_t* pl = m + 24;
    if (type == -1 || type == -2) {
      const std::uint32_t l = payload_len >= 4 ? be32(pl) : 0;
      if (l < 1 || l + 4 > payload_len || pl[4 + l - 1] != 0) {
        ++protocol_errors;
        return;
      }
      (type == -1 ? senders : types)[sender] = std::string(reinterpret_cast<const char*>(pl + 4));
      return;
    }
    if (type < 0 || types.count(type) == 0 || senders.count(sender) == 0) {
      ++protocol_errors;  // the server must describe before it uses an id
      return;
    }
    Report r;
    r.body = senders[sender];
    r.type = types[type];
    r.sec = static_cast<std::int32_t>(be32(m + 4));
    r.usec = static_cast<std::int32_t>(be32(m + 8));
    r.via_udp = udp;
    if (r.type == "vrpn_Tracker Pos_Quat" || r.type == "vrpn_Tracker Velocity") {
      const bool pq = r.type == "vrpn_Tracker Pos_Quat";
      if (payload_len != (pq ? 64u : 72u)) {
        ++protocol_errors;
        return;
      }
      r.sensor = static_cast<std::int32_t>(be32(pl));
      for (int i = 0; i < 3; ++i) (pq ? r.pos : r.vel)[i] = be64f(pl + 8 + 8 * i);
      for (int i = 0; i < 4; ++i) (pq ? r.quat : r.vel_quat)[i] = be64f(pl + 32 + 8 * i);
      if (!pq) r.dt = be64f(pl + 64);
      reports.push_back(r);
    } else {
      others.emplace_back(r.body, r.type);
    }
  }

  int tcp_ = -1, listen_ = -1, udp_in_ = -1;
  std::uint16_t listen_port_ = 0;
  std::vector<std::uint8_t> in_;
};

}  // namespace mocap::test::vrpn_client
