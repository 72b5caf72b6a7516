// Design: see vrpn_session.h. The message handling follows what a VRPN server endpoint
// does with a client's system messages (vrpn_Endpoint::handle_sender_message,
// handle_type_message, vrpn_Connection_IP::handle_UDP_message) and with ping messages
// (vrpn_BaseClassUnique::handle_ping).
#include "pipeline/publish/vrpn/vrpn_session.h"

#include <cstring>

namespace mocap::publish::vrpn {

void Session::reset() noexcept {
  used_ = 0;
  cookie_received_ = false;
  error_ = "";
  messages_ = 0;
  ping_type_ = -1;
  sender_body_.fill(-1);
}

bool Session::process(SessionActions& actions) noexcept {
  std::size_t at = 0;
  if (!cookie_received_) {
    if (used_ < kCookieBytes) return true;
    if (!cookie_ok(input_.data())) return fail("not a VRPN 07 cookie");
    cookie_received_ = true;
    at = kCookieBytes;
  }
  while (at < used_) {
    MessageView m;
    const ParseStatus st = parse_message(input_.data() + at, used_ - at, kMaxMessageBytes, m);
    if (st == ParseStatus::kError) return fail("message length out of bounds");
    if (st == ParseStatus::kNeedMore) break;
    ++messages_;
    if (!handle(m, actions)) return false;
    at += m.total_bytes;
  }
  if (at > 0) {  // keep the incomplete rest at the start
    std::memmove(input_.data(), input_.data() + at, used_ - at);
    used_ -= at;
  }
  return true;
}

bool Session::handle(const MessageView& m, SessionActions& actions) noexcept {
  const std::int32_t type = m.header.type;
  const std::int32_t id = m.header.sender;
  switch (type) {
    case kSenderDescription:
    case kTypeDescription: {
      std::string_view name;
      if (!parse_name_payload(m.payload, m.payload_len, name)) return fail("bad name description");
      if (id < 0) return fail("negative id described");
      if (id >= kMaxRemoteIds) return true;  // beyond what we map: ignored
      if (type == kTypeDescription) {
        if (name == kPingType) ping_type_ = id;
        return true;
      }
      sender_body_[static_cast<std::size_t>(id)] = -1;
      for (std::size_t b = 0; b < bodies_->size(); ++b) {
        if ((*bodies_)[b] == name)
          sender_body_[static_cast<std::size_t>(id)] = static_cast<std::int16_t>(b);
      }
      return true;
    }
    case kUdpDescription: {
      // sender = the client's UDP port; payload = its host name (we send to the TCP
      // peer's address instead, see docs/vrpn.md); a NUL must end it.
      if (m.payload_len == 0 || m.payload_len > kMaxNameBytes ||
          m.payload[m.payload_len - 1] != '\0')
        return fail("bad UDP description");
      if (id < 1 || id > 65535) return fail("UDP description port out of range");
      actions.udp_port = static_cast<std::uint16_t>(id);
      return true;
    }
    case kLogDescription:
    case kDisconnectMessage:
      return true;  // we keep no logs; a disconnect ends the connection at TCP level
    default:
      break;
  }
  if (type < 0) return fail("unknown system message");
  if (type == ping_type_ && id >= 0 && id < kMaxRemoteIds) {
    const std::int16_t body = sender_body_[static_cast<std::size_t>(id)];
    if (body >= 0 && actions.pong_count < kMaxPongs) {
      actions.pongs[static_cast<std::size_t>(actions.pong_count++)] = body;
    }
  }
  return true;  // other user messages (tracker requests, text) are ignored
}

}  // namespace mocap::publish::vrpn
