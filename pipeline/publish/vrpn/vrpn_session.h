// Design: the protocol state of ONE connected VRPN client, without its socket: what the
// client sends is buffered in a fixed input buffer (kInputBytes) and parsed here; the
// server (vrpn_server.h) reads the socket into space()/commit() and acts on the
// SessionActions. The client's bytes are never trusted: its cookie must come first
// (cookie_ok), every message length is bounded (kMaxMessageBytes, larger: error), a
// name description must be well formed, and ids beyond kMaxRemoteIds are ignored. Any
// violation ends THIS session (the server closes the connection and counts it).
// What a client may ask of us:
//   - sender descriptions: names of its objects; a sender named as one of our bodies is
//     how its pings reach that body's tracker;
//   - type descriptions: only "vrpn_Base ping_message" matters (answered with a pong
//     from the same-named sender, as vrpn_BaseClassUnique::handle_ping does; a client
//     without pongs warns "No response from server");
//   - a UDP description: the port where it wants the unreliable (tracker) messages;
//   - anything else (log description, its own user messages such as tracker requests):
//     parsed, bounded and ignored.
// No allocation after construction: the session lives in a preallocated client slot.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "pipeline/publish/vrpn/vrpn_wire.h"

namespace mocap::publish::vrpn {

inline constexpr std::size_t kInputBytes = 4096;       // buffered client bytes
inline constexpr std::size_t kMaxMessageBytes = 1024;  // a client message, header included
inline constexpr int kMaxRemoteIds = 256;              // client sender/type ids we map
inline constexpr int kMaxPongs = 16;                   // pongs owed per process() call

struct SessionActions {
  std::array<std::int32_t, kMaxPongs> pongs{};  // our sender ids (body indices) to pong
  int pong_count = 0;
  std::uint16_t udp_port = 0;  // nonzero: the client listens for UDP data on this port
};

class Session {
 public:
  // `bodies`: our sender names (body index = sender id); must outlive the session.
  explicit Session(const std::vector<std::string>* bodies) : bodies_(bodies) { reset(); }

  void reset() noexcept;  // a new connection

  // Where the next received bytes go and how many fit (0: buffer full, process first).
  std::uint8_t* space() noexcept { return input_.data() + used_; }
  std::size_t space_bytes() const noexcept { return input_.size() - used_; }
  void commit(std::size_t n) noexcept { used_ = n <= space_bytes() ? used_ + n : input_.size(); }

  // Parses every complete item buffered. False: protocol error, see error(); the
  // session must then be closed. Pongs beyond kMaxPongs in one call are left out.
  bool process(SessionActions& actions) noexcept;

  bool cookie_received() const noexcept { return cookie_received_; }
  const char* error() const noexcept { return error_; }
  std::uint64_t messages() const noexcept { return messages_; }

 private:
  bool handle(const MessageView& m, SessionActions& actions) noexcept;
  bool fail(const char* why) noexcept {
    error_ = why;
    return false;
  }

  const std::vector<std::string>* bodies_;
  std::array<std::uint8_t, kInputBytes> input_{};
  std::size_t used_ = 0;
  bool cookie_received_ = false;
  const char* error_ = "";
  std::uint64_t messages_ = 0;
  std::int32_t ping_type_ = -1;                            // the client's id of ping_message
  std::array<std::int16_t, kMaxRemoteIds> sender_body_{};  // client sender id -> body, -1
};

}  // namespace mocap::publish::vrpn
