// Design: see udp_endpoint.h. The port is parsed by hand (strict digits, range checked)
// so "host:80x" or "host:99999" are rejected with a precise message.
#include "client/udp_endpoint.h"

#include <netdb.h>
#include <sys/socket.h>

#include <cstring>

namespace mocap::client {

Expected<sockaddr_in> parse_udp_endpoint(const std::string& host_port, const std::string& context) {
  const auto fail = [&](const std::string& what) {
    return make_error(context, "'" + host_port + "'", what);
  };
  const std::size_t colon = host_port.rfind(':');
  if (colon == std::string::npos) return fail("expected HOST:PORT");
  const std::string host = host_port.substr(0, colon);
  const std::string port_text = host_port.substr(colon + 1);
  if (host.empty()) return fail("empty host");
  if (port_text.empty() || port_text.size() > 5) return fail("port must be 0..65535");
  unsigned port = 0;
  for (char ch : port_text) {
    if (ch < '0' || ch > '9') return fail("port must be 0..65535");
    port = port * 10u + static_cast<unsigned>(ch - '0');
  }
  if (port > 65535u) return fail("port must be 0..65535");

  addrinfo hints{};
  hints.ai_family = AF_INET;
  hints.ai_socktype = SOCK_DGRAM;
  addrinfo* res = nullptr;
  const int rc = ::getaddrinfo(host.c_str(), nullptr, &hints, &res);
  if (rc != 0 || res == nullptr) {
    return fail(std::string("cannot resolve host (") + ::gai_strerror(rc) + ")");
  }
  sockaddr_in addr{};
  std::memcpy(&addr, res->ai_addr, sizeof(addr));
  ::freeaddrinfo(res);
  addr.sin_family = AF_INET;
  addr.sin_port = htons(static_cast<std::uint16_t>(port));
  return addr;
}

}  // namespace mocap::client
