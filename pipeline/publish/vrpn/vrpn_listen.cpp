// Design: see vrpn_listen.h.
#include "pipeline/publish/vrpn/vrpn_listen.h"

#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

#include "core/listen_address.h"

namespace mocap::publish::vrpn {

Expected<void> parse_listen_address(const std::string& text, const std::string& key,
                                    ServerOptions& options) {
  auto a = mocap::parse_listen_address(text, key, options.address, IpFamilies::kIpv4);
  if (!a) return a.error();
  options.address = a->address;
  options.port = a->port;
  return {};
}

namespace {

Expected<ListenSockets> try_bind(const ServerOptions& o, std::uint16_t port, bool& retry) {
  retry = false;
  const std::string where = o.address + ":" + std::to_string(port);
  sockaddr_in sa{};
  sa.sin_family = AF_INET;
  sa.sin_port = htons(port);
  if (::inet_pton(AF_INET, o.address.c_str(), &sa.sin_addr) != 1)
    return make_error(where, "", "not an IPv4 address");
  ListenSockets s;
  auto fail = [&](const char* what) {
    const int e = errno;
    if (s.tcp >= 0) ::close(s.tcp);
    if (s.udp >= 0) ::close(s.udp);
    return make_error(where, "", std::string(what) + ": " + std::strerror(e));
  };
  s.tcp = ::socket(AF_INET, SOCK_STREAM | SOCK_NONBLOCK | SOCK_CLOEXEC, 0);
  if (s.tcp < 0) return fail("cannot listen");
  const int one = 1;
  ::setsockopt(s.tcp, SOL_SOCKET, SO_REUSEADDR, &one, sizeof one);  // restart in TIME_WAIT
  if (::bind(s.tcp, reinterpret_cast<const sockaddr*>(&sa), sizeof sa) != 0 ||
      ::listen(s.tcp, 16) != 0)
    return fail("cannot listen");
  sockaddr_in bound{};
  socklen_t len = sizeof bound;
  ::getsockname(s.tcp, reinterpret_cast<sockaddr*>(&bound), &len);
  s.port = ntohs(bound.sin_port);
  sa.sin_port = bound.sin_port;
  s.udp = ::socket(AF_INET, SOCK_DGRAM | SOCK_NONBLOCK | SOCK_CLOEXEC, 0);
  if (s.udp < 0) return fail("cannot open the UDP socket");
  if (::bind(s.udp, reinterpret_cast<const sockaddr*>(&sa), sizeof sa) != 0) {
    retry = port == 0 && errno == EADDRINUSE;  // a free TCP port whose UDP twin is taken
    return fail("cannot bind UDP (connection requests)");
  }
  return s;
}

}  // namespace

Expected<ListenSockets> open_listen_sockets(const ServerOptions& options) {
  for (int attempt = 0;; ++attempt) {
    bool retry = false;
    auto s = try_bind(options, options.port, retry);
    if (s || !retry || attempt >= 20) return s;
  }
}

}  // namespace mocap::publish::vrpn
