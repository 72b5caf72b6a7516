// Design: the setup half of the VRPN server's sockets: "[ADDRESS:]PORT" parsing and the
// TCP listener + UDP socket bound to the same IPv4 address and port (VRPN takes
// connection requests by UDP and connections by TCP on one port number). Setup code:
// one-line errors naming the request's key and the address.
#pragma once

#include <cstdint>
#include <string>

#include "core/expected.h"
#include "pipeline/publish/vrpn/vrpn_server.h"

namespace mocap::publish::vrpn {

struct ListenSockets {
  int tcp = -1;  // listening, non-blocking
  int udp = -1;  // bound, non-blocking
  std::uint16_t port = 0;
};

// Binds both on options.address:options.port (port 0: one free port for both).
// Error: "ADDRESS:PORT: cannot listen: <reason>".
Expected<ListenSockets> open_listen_sockets(const ServerOptions& options);

}  // namespace mocap::publish::vrpn
