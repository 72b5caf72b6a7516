// Design: fuzz entry point of the VRPN server's input side (pipeline/publish/vrpn): what
// a client sends over TCP (the per-client Session: cookie, framing, descriptions, pings,
// UDP description) and what anyone sends to the UDP port (connection requests). The
// first byte selects the mode: bit 0 set: prepend a valid cookie (gets the fuzzer past
// it); bit 1 set: the rest is a UDP connection request instead; bits 2..7 = the chunk
// size in which the stream reaches the session (1..64 bytes: every split point of a
// message). Properties: the session never owes more pongs than kMaxPongs, only for our
// bodies; an error has a reason and ends the stream; the framing decoder's view stays
// inside the bytes given; a request's port is 1024..65535.
#include <algorithm>
#include <cstring>
#include <string>
#include <vector>

#include "pipeline/publish/vrpn/vrpn_session.h"
#include "pipeline/publish/vrpn/vrpn_wire.h"
#include "tests/fuzz/fuzz_targets.h"

namespace mocap::fuzz {

int fuzz_vrpn(const std::uint8_t* data, std::size_t size) {
  using namespace mocap::publish::vrpn;
  if (size == 0) return 0;
  const std::uint8_t mode = data[0];
  ++data;
  --size;
  if ((mode & 2u) != 0) {
    std::uint16_t port = 0;
    if (parse_connection_request(data, size, port))
      fuzz_check(port >= 1024, "connection request port below 1024");
    return 0;
  }
  std::vector<std::uint8_t> stream;
  if ((mode & 1u) != 0) {
    stream.resize(kCookieBytes);
    write_cookie(stream.data());
  }
  stream.insert(stream.end(), data, data + size);
  // The framing decoder on the raw bytes (after the cookie).
  const std::size_t body = (mode & 1u) != 0 ? kCookieBytes : 0;
  for (std::size_t at = body; at < stream.size();) {
    MessageView v;
    const ParseStatus st =
        parse_message(stream.data() + at, stream.size() - at, kMaxMessageBytes, v);
    if (st != ParseStatus::kMessage) break;
    fuzz_check(v.total_bytes >= kHeaderBytes && v.total_bytes % kAlign == 0 &&
                   v.total_bytes <= stream.size() - at &&
                   v.payload_len + kHeaderBytes == v.header.length,
               "message view outside the bytes");
    std::string_view name;
    if (parse_name_payload(v.payload, v.payload_len, name))
      fuzz_check(name.size() <= kMaxNameChars && name.find('\0') == std::string_view::npos,
                 "name description");
    at += v.total_bytes;
  }
  // The session, fed in chunks as a socket would deliver them.
  static const std::vector<std::string> bodies = {"arm", "hand", "head"};
  Session s(&bodies);
  const std::size_t chunk = 1 + (mode >> 2);
  for (std::size_t at = 0; at < stream.size();) {
    const std::size_t n = std::min({chunk, stream.size() - at, s.space_bytes()});
    fuzz_check(n > 0, "session input buffer stuck full");
    std::memcpy(s.space(), stream.data() + at, n);
    s.commit(n);
    at += n;
    SessionActions a;
    if (!s.process(a)) {
      fuzz_check(std::strlen(s.error()) > 0, "error without a reason");
      return 0;
    }
    fuzz_check(a.pong_count >= 0 && a.pong_count <= kMaxPongs, "pong count");
    for (int i = 0; i < a.pong_count; ++i)
      fuzz_check(
          a.pongs[static_cast<std::size_t>(i)] >= 0 &&
              a.pongs[static_cast<std::size_t>(i)] < static_cast<std::int32_t>(bodies.size()),
          "pong for a sender that is not ours");
  }
  return 0;
}

}  // namespace mocap::fuzz
