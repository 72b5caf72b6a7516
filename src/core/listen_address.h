// Design: the one parser of a listening socket's "[ADDRESS:]PORT" (the values of
// `--foxglove`, `--vrpn` and their `outputs:` keys): ADDRESS defaults to the caller's
// (127.0.0.1: a listening socket is local unless configured otherwise), PORT is 0..65535
// (0: any free port), an IPv6 address goes in brackets ("[::1]:8765") where the server
// takes IPv6. Numeric addresses only (no name lookup at setup). Errors are one line
// naming `key`: "--vrpn: 'localhost:3883': 'localhost' is not an IPv4 address".
#pragma once

#include <cstdint>
#include <string>

#include "core/expected.h"

namespace mocap {

struct ListenAddress {
  std::string address;
  std::uint16_t port = 0;
};

enum class IpFamilies : std::uint8_t { kIpv4, kIpv4AndIpv6 };

Expected<ListenAddress> parse_listen_address(const std::string& text, const std::string& key,
                                             const std::string& default_address,
                                             IpFamilies families);

}  // namespace mocap
