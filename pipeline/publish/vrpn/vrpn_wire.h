// Design: VRPN's wire format (protocol major version 7), written from VRPN's own source
// (vrpn/vrpn: vrpn_Connection.h/.C, vrpn_Tracker.C, vrpn_Shared.C; docs/vrpn.md lists
// which functions each piece follows), no VRPN code copied. Pure functions on byte
// buffers, no sockets, no allocation: the server (vrpn_server.h) and the per-client
// protocol state (vrpn_session.h) are built on them, and the fuzz target drives them.
//   cookie   24 bytes: "vrpn: ver. 07.MM" (16), two spaces, the remote log mode as one
//            ASCII digit '0'..'3', then NULs. Both sides send one on connecting; a peer
//            is accepted when its cookie matches through the last '.' (any 07 minor).
//   message  header of five big-endian 32-bit words (length, time sec, time usec,
//            sender, type) plus a sequence number, padded to 24 bytes (vrpn_ALIGN = 8);
//            length = 24 + payload length (without padding); the payload follows,
//            padded with zeros to a multiple of 8 bytes.
//   system   negative types: -1 sender description and -2 type description (sender
//            field = the id described; payload = int32 name length including its NUL,
//            then the name and NUL), -3 UDP description (sender field = the UDP port
//            the peer listens on; payload = its host as a NUL-terminated string), -4 log
//            description, -5 disconnect.
//   requests A client that cannot be reached by TCP first lobs "HOST PORT\0" in a UDP
//            datagram to the server's port; the server connects back to PORT over TCP.
//   tracker  Pos_Quat payload (64 bytes): int32 sensor, int32 (sensor again, padding),
//            float64 pos[3] (metres), float64 quat[4] in VRPN's order x, y, z, w.
//            Velocity payload (72 bytes): int32 sensor, int32 padding, float64 vel[3]
//            (m/s), float64 vel_quat[4] (x, y, z, w: the rotation over vel_quat_dt),
//            float64 vel_quat_dt (seconds). All numbers big-endian (IEEE 754 doubles).
#pragma once

#include <cstddef>
#include <cstdint>
#include <string_view>

namespace mocap::publish::vrpn {

inline constexpr std::size_t kAlign = 8;           // vrpn_ALIGN
inline constexpr std::size_t kCookieBytes = 24;    // vrpn_cookie_size(): 16 + kAlign
inline constexpr std::size_t kHeaderBytes = 24;    // 5 x int32 (+ sequence) padded to 8
inline constexpr std::size_t kMaxNameBytes = 100;  // vrpn_CNAME: a description's whole payload
// The longest sender/type name: VRPN refuses a description payload (length word + name +
// NUL) longer than vrpn_CNAME (handle_sender_message), so 100 - 4 - 1 characters.
inline constexpr std::size_t kMaxNameChars = kMaxNameBytes - 5;
inline constexpr std::size_t kUdpPayloadBytes = 1472;  // vrpn_CONNECTION_UDP_BUFLEN
inline constexpr std::size_t kPosQuatPayloadBytes = 64;
inline constexpr std::size_t kVelocityPayloadBytes = 72;
inline constexpr std::uint16_t kDefaultPort = 3883;  // vrpn_DEFAULT_LISTEN_PORT_NO

inline constexpr std::int32_t kSenderDescription = -1;
inline constexpr std::int32_t kTypeDescription = -2;
inline constexpr std::int32_t kUdpDescription = -3;
inline constexpr std::int32_t kLogDescription = -4;
inline constexpr std::int32_t kDisconnectMessage = -5;

inline constexpr std::string_view kPosQuatType = "vrpn_Tracker Pos_Quat";
inline constexpr std::string_view kVelocityType = "vrpn_Tracker Velocity";
inline constexpr std::string_view kPingType = "vrpn_Base ping_message";
inline constexpr std::string_view kPongType = "vrpn_Base pong_message";

// The message times of VRPN (struct timeval on the wire: two 32-bit words).
struct WireTime {
  std::int32_t sec = 0;
  std::int32_t usec = 0;  // 0..999999
};
// A CLOCK_REALTIME time in ns (negative: 0; beyond 2038: clamped).
WireTime wire_time(std::int64_t realtime_ns) noexcept;

struct MessageHeader {
  std::uint32_t length = 0;  // kHeaderBytes + payload length (no padding)
  WireTime time;
  std::int32_t sender = 0;
  std::int32_t type = 0;
  std::uint32_t sequence = 0;
};

// Big-endian scalars.
void put_u32(std::uint8_t* out, std::uint32_t v) noexcept;
void put_f64(std::uint8_t* out, double v) noexcept;
std::uint32_t get_u32(const std::uint8_t* in) noexcept;
double get_f64(const std::uint8_t* in) noexcept;

constexpr std::size_t padded(std::size_t n) noexcept { return (n + kAlign - 1) / kAlign * kAlign; }
constexpr std::size_t message_bytes(std::size_t payload_len) noexcept {
  return kHeaderBytes + padded(payload_len);
}

// Our cookie (kCookieBytes bytes, log mode 0).
void write_cookie(std::uint8_t* out) noexcept;
// A peer's cookie (kCookieBytes bytes): "vrpn: ver. 07." then a two-digit minor and a
// log mode digit '0'..'3' at offset 18.
bool cookie_ok(const std::uint8_t* in) noexcept;

// Header + payload + zero padding into out[0, cap). Bytes written; 0 when it does not
// fit.
std::size_t write_message(std::uint8_t* out, std::size_t cap, std::int32_t type,
                          std::int32_t sender, WireTime time, std::uint32_t sequence,
                          const std::uint8_t* payload, std::size_t payload_len) noexcept;

// Sender/type description payload of `name` (1..kMaxNameChars chars): bytes written
// to out[0, cap), 0 when it does not fit or the name is empty/too long.
std::size_t write_name_payload(std::uint8_t* out, std::size_t cap, std::string_view name) noexcept;

void write_pos_quat(std::uint8_t* out, std::int32_t sensor, const double (&pos_m)[3],
                    const double (&quat_xyzw)[4]) noexcept;  // kPosQuatPayloadBytes
void write_velocity(std::uint8_t* out, std::int32_t sensor, const double (&vel_m_s)[3],
                    const double (&dquat_xyzw)[4], double dt_s) noexcept;  // kVelocityPayloadBytes

// One message at the start of in[0, n). Never trusts the length field: a length below
// the header, above max_message_bytes or with a padded size beyond it is an error.
enum class ParseStatus { kNeedMore, kMessage, kError };
struct MessageView {
  MessageHeader header;
  const std::uint8_t* payload = nullptr;
  std::size_t payload_len = 0;
  std::size_t total_bytes = 0;  // header + padded payload: where the next message starts
};
ParseStatus parse_message(const std::uint8_t* in, std::size_t n, std::size_t max_message_bytes,
                          MessageView& out) noexcept;

// A sender/type description payload: the name (without NUL) when well formed: length
// payload at most kMaxNameBytes, length word >= 1, the name within the payload,
// NUL-terminated, no NUL inside.
bool parse_name_payload(const std::uint8_t* payload, std::size_t n,
                        std::string_view& name) noexcept;

// A UDP connection request "HOST PORT" (NUL-terminated or not, at most 200 bytes): HOST
// letters, digits and dots (as VRPN checks it), PORT 1024..65535. The server connects
// back to the datagram's source address, not to HOST (docs/vrpn.md).
bool parse_connection_request(const std::uint8_t* datagram, std::size_t n,
                              std::uint16_t& port) noexcept;

}  // namespace mocap::publish::vrpn
