// Design: see vrpn_wire.h. Encoding follows vrpn_Endpoint::marshall_message (header and
// padding), write_vrpn_cookie / check_vrpn_cookie (cookie), pack_sender_description /
// pack_type_description (descriptions), vrpn_Tracker::encode_to / encode_vel_to
// (reports), vrpn_buffer / vrpn_htond (big-endian doubles), and
// server_check_for_incoming_connections (the UDP request's checks).
#include "pipeline/publish/vrpn/vrpn_wire.h"

#include <cctype>
#include <cstring>
#include <limits>

namespace mocap::publish::vrpn {

namespace {
constexpr char kMagicPrefix[] = "vrpn: ver. 07.";  // through the last '.'
constexpr char kMagic[] = "vrpn: ver. 07.38";      // 16 characters
}  // namespace

WireTime wire_time(std::int64_t realtime_ns) noexcept {
  if (realtime_ns < 0) realtime_ns = 0;
  const std::int64_t sec = realtime_ns / 1'000'000'000;
  WireTime t;
  if (sec > std::numeric_limits<std::int32_t>::max()) {
    t.sec = std::numeric_limits<std::int32_t>::max();
    t.usec = 999'999;
    return t;
  }
  t.sec = static_cast<std::int32_t>(sec);
  t.usec = static_cast<std::int32_t>((realtime_ns % 1'000'000'000) / 1000);
  return t;
}

void put_u32(std::uint8_t* out, std::uint32_t v) noexcept {
  out[0] = static_cast<std::uint8_t>(v >> 24);
  out[1] = static_cast<std::uint8_t>(v >> 16);
  out[2] = static_cast<std::uint8_t>(v >> 8);
  out[3] = static_cast<std::uint8_t>(v);
}

void put_f64(std::uint8_t* out, double v) noexcept {
  std::uint64_t bits = 0;
  std::memcpy(&bits, &v, sizeof bits);
  for (int i = 0; i < 8; ++i) out[i] = static_cast<std::uint8_t>(bits >> (56 - 8 * i));
}

std::uint32_t get_u32(const std::uint8_t* in) noexcept {
  return (std::uint32_t{in[0]} << 24) | (std::uint32_t{in[1]} << 16) | (std::uint32_t{in[2]} << 8) |
         std::uint32_t{in[3]};
}

double get_f64(const std::uint8_t* in) noexcept {
  std::uint64_t bits = 0;
  for (int i = 0; i < 8; ++i) bits = (bits << 8) | in[i];
  double v = 0.0;
  std::memcpy(&v, &bits, sizeof v);
  return v;
}

void write_cookie(std::uint8_t* out) noexcept {
  std::memset(out, 0, kCookieBytes);
  std::memcpy(out, kMagic, 16);
  out[16] = ' ';
  out[17] = ' ';
  out[18] = '0';  // no remote logging asked of the client
}

bool cookie_ok(const std::uint8_t* in) noexcept {
  constexpr std::size_t prefix = sizeof kMagicPrefix - 1;
  if (std::memcmp(in, kMagicPrefix, prefix) != 0) return false;
  for (std::size_t i = prefix; i < 16; ++i)
    if (in[i] < '0' || in[i] > '9') return false;
  return in[18] >= '0' && in[18] <= '3';
}

std::size_t write_message(std::uint8_t* out, std::size_t cap, std::int32_t type,
                          std::int32_t sender, WireTime time, std::uint32_t sequence,
                          const std::uint8_t* payload, std::size_t payload_len) noexcept {
  const std::size_t total = message_bytes(payload_len);
  if (total > cap || payload_len > std::numeric_limits<std::uint32_t>::max() - kHeaderBytes)
    return 0;
  put_u32(out, static_cast<std::uint32_t>(kHeaderBytes + payload_len));
  put_u32(out + 4, static_cast<std::uint32_t>(time.sec));
  put_u32(out + 8, static_cast<std::uint32_t>(time.usec));
  put_u32(out + 12, static_cast<std::uint32_t>(sender));
  put_u32(out + 16, static_cast<std::uint32_t>(type));
  put_u32(out + 20, sequence);
  if (payload_len > 0) std::memcpy(out + kHeaderBytes, payload, payload_len);
  std::memset(out + kHeaderBytes + payload_len, 0, total - kHeaderBytes - payload_len);
  return total;
}

std::size_t write_name_payload(std::uint8_t* out, std::size_t cap, std::string_view name) noexcept {
  const std::size_t with_nul = name.size() + 1;
  if (name.empty() || name.size() > kMaxNameChars || 4 + with_nul > cap) return 0;
  put_u32(out, static_cast<std::uint32_t>(with_nul));
  std::memcpy(out + 4, name.data(), name.size());
  out[4 + name.size()] = 0;
  return 4 + with_nul;
}

void write_pos_quat(std::uint8_t* out, std::int32_t sensor, const double (&pos_m)[3],
                    const double (&quat_xyzw)[4]) noexcept {
  put_u32(out, static_cast<std::uint32_t>(sensor));
  put_u32(out + 4, static_cast<std::uint32_t>(sensor));  // padding to 8, as VRPN fills it
  for (int i = 0; i < 3; ++i) put_f64(out + 8 + 8 * i, pos_m[i]);
  for (int i = 0; i < 4; ++i) put_f64(out + 32 + 8 * i, quat_xyzw[i]);
}

void write_velocity(std::uint8_t* out, std::int32_t sensor, const double (&vel_m_s)[3],
                    const double (&dquat_xyzw)[4], double dt_s) noexcept {
  put_u32(out, static_cast<std::uint32_t>(sensor));
  put_u32(out + 4, static_cast<std::uint32_t>(sensor));
  for (int i = 0; i < 3; ++i) put_f64(out + 8 + 8 * i, vel_m_s[i]);
  for (int i = 0; i < 4; ++i) put_f64(out + 32 + 8 * i, dquat_xyzw[i]);
  put_f64(out + 64, dt_s);
}

ParseStatus parse_message(const std::uint8_t* in, std::size_t n, std::size_t max_message_bytes,
                          MessageView& out) noexcept {
  if (n < 4) return ParseStatus::kNeedMore;
  const std::uint32_t length = get_u32(in);
  if (length < kHeaderBytes || length > max_message_bytes) return ParseStatus::kError;
  const std::size_t total = padded(length);
  if (total > padded(max_message_bytes)) return ParseStatus::kError;
  if (n < total) return ParseStatus::kNeedMore;
  out.header.length = length;
  out.header.time.sec = static_cast<std::int32_t>(get_u32(in + 4));
  out.header.time.usec = static_cast<std::int32_t>(get_u32(in + 8));
  out.header.sender = static_cast<std::int32_t>(get_u32(in + 12));
  out.header.type = static_cast<std::int32_t>(get_u32(in + 16));
  out.header.sequence = get_u32(in + 20);
  out.payload = in + kHeaderBytes;
  out.payload_len = length - kHeaderBytes;
  out.total_bytes = total;
  return ParseStatus::kMessage;
}

bool parse_name_payload(const std::uint8_t* payload, std::size_t n,
                        std::string_view& name) noexcept {
  if (n < 5 || n > kMaxNameBytes) return false;
  const std::uint32_t with_nul = get_u32(payload);
  if (with_nul < 1 || with_nul > n - 4) return false;
  const char* text = reinterpret_cast<const char*>(payload + 4);
  if (text[with_nul - 1] != '\0') return false;
  if (std::memchr(text, '\0', with_nul - 1) != nullptr) return false;
  name = std::string_view(text, with_nul - 1);
  return true;
}

bool parse_connection_request(const std::uint8_t* datagram, std::size_t n,
                              std::uint16_t& port) noexcept {
  if (n == 0 || n > 200) return false;
  if (datagram[n - 1] == '\0') --n;  // VRPN sends the terminating NUL
  std::size_t i = 0;
  while (i < n && (std::isalnum(datagram[i]) != 0 || datagram[i] == '.')) ++i;
  if (i == 0 || i >= n || datagram[i] != ' ') return false;
  ++i;
  std::uint32_t value = 0;
  std::size_t digits = 0;
  for (; i < n; ++i, ++digits) {
    if (datagram[i] < '0' || datagram[i] > '9' || digits >= 5) return false;
    value = value * 10 + static_cast<std::uint32_t>(datagram[i] - '0');
  }
  if (digits == 0 || value < 1024 || value > 65535) return false;
  port = static_cast<std::uint16_t>(value);
  return true;
}

}  // namespace mocap::publish::vrpn
