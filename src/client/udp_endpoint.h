// Design: "HOST:PORT" -> IPv4 socket address, resolved once at setup (getaddrinfo, which
// allocates and may block: never call it on the hot path). HOST is a dotted address or a
// name; PORT is 0..65535 (0 lets a receiver take an ephemeral port).
#pragma once

#include <netinet/in.h>

#include <string>

#include "core/expected.h"

namespace mocap::client {

// Errors read "<context>: '<host_port>': <problem>".
Expected<sockaddr_in> parse_udp_endpoint(const std::string& host_port, const std::string& context);

}  // namespace mocap::client
