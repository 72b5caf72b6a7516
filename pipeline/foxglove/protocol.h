// Design: the Foxglove WebSocket protocol (subprotocol "foxglove.websocket.v1") as pure
// functions and one small per-connection state machine, free of sockets and threads, so
// that the server (server.cpp) stays thin and this part can be unit-tested and fuzzed
// (bytes in -> verdict and subscription table out).
//   server -> client, text: serverInfo, advertise, status (JSON objects with "op");
//   server -> client, binary: Message Data = opcode 0x01, u32 subscription id, u64
//     timestamp (ns), payload; little-endian.
//   client -> server, text: subscribe {subscriptions:[{id, channelId}]}, unsubscribe
//     {subscriptionIds:[id]}.
// This server advertises no capabilities, so everything else a client sends (unknown
// op, bad JSON, a subscription to an unknown channel, a second subscription of a channel,
// a reused subscription id, binary frames, over-deep JSON) is a protocol violation: the
// verdict is "close this connection" with a one-line reason. Never throws.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <nlohmann/json_fwd.hpp>
#include <string>
#include <string_view>
#include <vector>

namespace mocap::foxglove {

inline constexpr char kSubprotocol[] = "foxglove.websocket.v1";
inline constexpr std::uint8_t kOpMessageData = 0x01;
inline constexpr std::size_t kMessageDataHeaderBytes = 13;  // opcode + u32 + u64
inline constexpr int kMaxJsonDepth = 8;                     // deeper client JSON is refused

// One advertised channel (JSON encoding, JSON-schema schemas).
struct ChannelInfo {
  std::uint32_t id = 0;
  std::string topic;        // "/tf"
  std::string schema_name;  // "foxglove.FrameTransforms"
  std::string schema;       // JSON schema (a JSON document as text)
};

enum class StatusLevel : int { kInfo = 0, kWarning = 1, kError = 2 };

std::string server_info_json(std::string_view server_name, std::string_view session_id);
std::string advertise_json(const std::vector<ChannelInfo>& channels);
std::string status_json(StatusLevel level, std::string_view message);

// The 13-byte header of a Message Data frame; the payload follows it.
std::array<std::uint8_t, kMessageDataHeaderBytes> message_data_header(
    std::uint32_t subscription_id, std::uint64_t timestamp_ns) noexcept;
// Inverse (for tests and diagnostics): false when the frame is too short or not 0x01.
bool parse_message_data_header(const std::uint8_t* data, std::size_t size,
                               std::uint32_t& subscription_id,
                               std::uint64_t& timestamp_ns) noexcept;

// Nesting depth of a JSON text (brackets outside strings), without parsing it; returns
// a value > limit as soon as the limit is exceeded.
int json_depth(std::string_view text, int limit) noexcept;

// The protocol state of one client connection: its subscriptions.
class ClientProtocol {
 public:
  explicit ClientProtocol(std::vector<std::uint32_t> channel_ids);

  // One text frame from the client. False: the connection must be closed; error() says
  // why (one line). Subscriptions change only when the whole message is valid.
  bool on_text(std::string_view text);
  // One binary frame from the client: always a violation here (no clientPublish).
  bool on_binary(std::size_t size);

  // The client's subscription id for this channel, or false when not subscribed.
  bool subscription_for(std::uint32_t channel_id, std::uint32_t& subscription_id) const noexcept;
  int subscription_count() const noexcept;
  const std::string& error() const noexcept { return error_; }

 private:
  struct Slot {
    std::uint32_t channel_id = 0;
    bool subscribed = false;
    std::uint32_t subscription_id = 0;
  };
  bool fail(std::string reason);
  bool handle_subscribe(const nlohmann::json& msg);
  bool handle_unsubscribe(const nlohmann::json& msg);

  std::vector<Slot> slots_;  // one per advertised channel
  std::string error_;
};

}  // namespace mocap::foxglove
