// Design: see protocol.h. JSON is parsed with nlohmann-json in its non-throwing mode
// (parse(..., allow_exceptions = false)) after a cheap depth pre-scan, and every field is
// type-checked before use, so hostile input never throws nor recurses deeply.
#include "pipeline/foxglove/protocol.h"

#include <nlohmann/json.hpp>

namespace mocap::foxglove {

using nlohmann::json;

std::string server_info_json(std::string_view server_name, std::string_view session_id) {
  json j = {{"op", "serverInfo"},
            {"name", std::string(server_name)},
            {"capabilities", json::array()},
            {"supportedEncodings", json::array()},
            {"metadata", json::object()},
            {"sessionId", std::string(session_id)}};
  return j.dump();
}

std::string advertise_json(const std::vector<ChannelInfo>& channels) {
  json list = json::array();
  for (const ChannelInfo& c : channels) {
    list.push_back({{"id", c.id},
                    {"topic", c.topic},
                    {"encoding", "json"},
                    {"schemaName", c.schema_name},
                    {"schema", c.schema},
                    {"schemaEncoding", "jsonschema"}});
  }
  return json({{"op", "advertise"}, {"channels", list}}).dump();
}

std::string status_json(StatusLevel level, std::string_view message) {
  // dump() with the replace handler: invalid UTF-8 in a message never throws.
  return json({{"op", "status"}, {"level", static_cast<int>(level)}, {"message", message}})
      .dump(-1, ' ', false, json::error_handler_t::replace);
}

std::array<std::uint8_t, kMessageDataHeaderBytes> message_data_header(
    std::uint32_t subscription_id, std::uint64_t timestamp_ns) noexcept {
  std::array<std::uint8_t, kMessageDataHeaderBytes> h{};
  h[0] = kOpMessageData;
  for (int i = 0; i < 4; ++i) h[1 + i] = static_cast<std::uint8_t>(subscription_id >> (8 * i));
  for (int i = 0; i < 8; ++i) h[5 + i] = static_cast<std::uint8_t>(timestamp_ns >> (8 * i));
  return h;
}

bool parse_message_data_header(const std::uint8_t* data, std::size_t size,
                               std::uint32_t& subscription_id,
                               std::uint64_t& timestamp_ns) noexcept {
  if (data == nullptr || size < kMessageDataHeaderBytes || data[0] != kOpMessageData) {
    return false;
  }
  subscription_id = 0;
  timestamp_ns = 0;
  for (int i = 0; i < 4; ++i) subscription_id |= std::uint32_t{data[1 + i]} << (8 * i);
  for (int i = 0; i < 8; ++i) timestamp_ns |= std::uint64_t{data[5 + i]} << (8 * i);
  return true;
}

int json_depth(std::string_view text, int limit) noexcept {
  int depth = 0;
  int max_depth = 0;
  bool in_string = false;
  bool escaped = false;
  for (const char c : text) {
    if (in_string) {
      if (escaped) {
        escaped = false;
      } else if (c == '\\') {
        escaped = true;
      } else if (c == '"') {
        in_string = false;
      }
      continue;
    }
    if (c == '"') {
      in_string = true;
    } else if (c == '[' || c == '{') {
      if (++depth > max_depth) max_depth = depth;
      if (max_depth > limit) return max_depth;
    } else if (c == ']' || c == '}') {
      --depth;
    }
  }
  return max_depth;
}

ClientProtocol::ClientProtocol(std::vector<std::uint32_t> channel_ids) {
  slots_.reserve(channel_ids.size());
  for (const std::uint32_t id : channel_ids) slots_.push_back(Slot{id, false, 0});
}

bool ClientProtocol::fail(std::string reason) {
  error_ = std::move(reason);
  return false;
}

bool ClientProtocol::on_binary(std::size_t size) {
  return fail("binary message of " + std::to_string(size) +
              " bytes: this server accepts no client-published data");
}

bool ClientProtocol::on_text(std::string_view text) {
  if (json_depth(text, kMaxJsonDepth) > kMaxJsonDepth) {
    return fail("JSON nested deeper than " + std::to_string(kMaxJsonDepth) + " levels");
  }
  const json msg = json::parse(text.begin(), text.end(), nullptr, false);
  if (msg.is_discarded()) return fail("message is not valid JSON");
  if (!msg.is_object()) return fail("message is not a JSON object");
  const auto op = msg.find("op");
  if (op == msg.end() || !op->is_string()) return fail("message has no string 'op'");
  const auto& name = op->get_ref<const std::string&>();
  if (name == "subscribe") return handle_subscribe(msg);
  if (name == "unsubscribe") return handle_unsubscribe(msg);
  std::string shown = name.substr(0, 40);
  return fail("unsupported op '" + shown + "' (this server has no capabilities)");
}

namespace {
// A non-negative integer that fits u32, or false.
bool get_u32(const json& obj, const char* key, std::uint32_t& out) {
  const auto it = obj.find(key);
  if (it == obj.end() || !it->is_number_integer()) return false;
  if (it->is_number_unsigned()) {
    const auto v = it->get<std::uint64_t>();
    if (v > 0xFFFFFFFFull) return false;
    out = static_cast<std::uint32_t>(v);
    return true;
  }
  const auto v = it->get<std::int64_t>();
  if (v < 0 || v > 0xFFFFFFFFll) return false;
  out = static_cast<std::uint32_t>(v);
  return true;
}
}  // namespace

bool ClientProtocol::handle_subscribe(const json& msg) {
  const auto subs = msg.find("subscriptions");
  if (subs == msg.end() || !subs->is_array()) {
    return fail("subscribe: 'subscriptions' is not an array");
  }
  std::vector<Slot> next = slots_;  // applied only when the whole message is valid
  for (const json& s : *subs) {
    std::uint32_t id = 0;
    std::uint32_t channel = 0;
    if (!s.is_object() || !get_u32(s, "id", id) || !get_u32(s, "channelId", channel)) {
      return fail("subscribe: each subscription needs integer 'id' and 'channelId' (u32)");
    }
    Slot* target = nullptr;
    for (Slot& slot : next) {
      if (slot.subscribed && slot.subscription_id == id) {
        return fail("subscribe: subscription id " + std::to_string(id) + " is already in use");
      }
      if (slot.channel_id == channel) target = &slot;
    }
    if (target == nullptr) {
      return fail("subscribe: channel " + std::to_string(channel) + " is not advertised");
    }
    if (target->subscribed) {
      return fail("subscribe: channel " + std::to_string(channel) + " is already subscribed");
    }
    target->subscribed = true;
    target->subscription_id = id;
  }
  slots_ = std::move(next);
  return true;
}

bool ClientProtocol::handle_unsubscribe(const json& msg) {
  const auto ids = msg.find("subscriptionIds");
  if (ids == msg.end() || !ids->is_array()) {
    return fail("unsubscribe: 'subscriptionIds' is not an array");
  }
  std::vector<Slot> next = slots_;
  for (const json& v : *ids) {
    const json holder = {{"id", v}};
    std::uint32_t id = 0;
    if (!get_u32(holder, "id", id)) return fail("unsubscribe: ids must be integers (u32)");
    bool found = false;
    for (Slot& slot : next) {
      if (slot.subscribed && slot.subscription_id == id) {
        slot.subscribed = false;
        found = true;
      }
    }
    if (!found) return fail("unsubscribe: unknown subscription id " + std::to_string(id));
  }
  slots_ = std::move(next);
  return true;
}

bool ClientProtocol::subscription_for(std::uint32_t channel_id,
                                      std::uint32_t& subscription_id) const noexcept {
  for (const Slot& slot : slots_) {
    if (slot.channel_id == channel_id && slot.subscribed) {
      subscription_id = slot.subscription_id;
      return true;
    }
  }
  return false;
}

int ClientProtocol::subscription_count() const noexcept {
  int n = 0;
  for (const Slot& slot : slots_) n += slot.subscribed ? 1 : 0;
  return n;
}

}  // namespace mocap::foxglove
