// Design: see listen_address.h.
#include "core/listen_address.h"

#include <arpa/inet.h>
#include <netinet/in.h>

namespace mocap {

Expected<ListenAddress> parse_listen_address(const std::string& text, const std::string& key,
                                             const std::string& default_address,
                                             IpFamilies families) {
  const bool v6 = families == IpFamilies::kIpv4AndIpv6;
  ListenAddress out{default_address, 0};
  std::string port_text = text;
  const auto colon = text.rfind(':');
  if (colon != std::string::npos) {
    out.address = text.substr(0, colon);
    port_text = text.substr(colon + 1);
    if (v6 && out.address.size() > 2 && out.address.front() == '[' && out.address.back() == ']')
      out.address = out.address.substr(1, out.address.size() - 2);  // [::1]
  }
  if (port_text.empty() || port_text.size() > 5 ||
      port_text.find_first_not_of("0123456789") != std::string::npos ||
      std::stoul(port_text) > 65535)
    return make_error(key, "'" + text + "'", "expected [ADDRESS:]PORT with PORT 0..65535");
  in_addr a4{};
  in6_addr a6{};
  const bool ok = ::inet_pton(AF_INET, out.address.c_str(), &a4) == 1 ||
                  (v6 && ::inet_pton(AF_INET6, out.address.c_str(), &a6) == 1);
  if (!ok)
    return make_error(key, "'" + text + "'",
                      "'" + out.address + "' is not an " + (v6 ? "IP" : "IPv4") + " address");
  out.port = static_cast<std::uint16_t>(std::stoul(port_text));
  return out;
}

}  // namespace mocap
