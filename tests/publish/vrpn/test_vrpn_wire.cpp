// VRPN's wire format (pipeline/publish/vrpn/vrpn_wire.h) against bytes written out by
// hand from VRPN's source (vrpn_Connection.C marshall_message / write_vrpn_cookie,
// vrpn_Tracker.C encode_to): the cookie, the 24-byte header and 8-byte padding, a name
// description, a Pos_Quat payload (big-endian doubles), the decoder's bounds (lengths
// never trusted), the UDP connection request's checks; and the per-client session
// (vrpn_session.h): cookie first, descriptions, ping -> pong, UDP description, errors.
#include <gtest/gtest.h>

#include <cstring>
#include <string>
#include <vector>

#include "pipeline/publish/vrpn/vrpn_session.h"
#include "pipeline/publish/vrpn/vrpn_wire.h"

namespace mocap::publish::vrpn {
namespace {

std::vector<std::uint8_t> bytes_of(const std::string& s) { return {s.begin(), s.end()}; }

TEST(VrpnWire, CookieIsTwentyFourBytesAndAnySeven0MinorIsAccepted) {
  std::uint8_t c[kCookieBytes];
  write_cookie(c);
  EXPECT_EQ(std::string(reinterpret_cast<char*>(c), 19), "vrpn: ver. 07.38  0");
  for (std::size_t i = 19; i < kCookieBytes; ++i) EXPECT_EQ(c[i], 0);
  EXPECT_TRUE(cookie_ok(c));
  std::memcpy(c, "vrpn: ver. 07.35", 16);
  EXPECT_TRUE(cookie_ok(c));
  std::memcpy(c, "vrpn: ver. 06.35", 16);
  EXPECT_FALSE(cookie_ok(c));
  std::memcpy(c, "vrpn: ver. 07.3x", 16);
  EXPECT_FALSE(cookie_ok(c));
  std::memcpy(c, "vrpn: ver. 07.35", 16);
  c[18] = '9';  // not a log mode
  EXPECT_FALSE(cookie_ok(c));
}

TEST(VrpnWire, MessageHeaderPaddingAndPosQuatAreBigEndian) {
  std::uint8_t payload[kPosQuatPayloadBytes];
  write_pos_quat(payload, 0, {1.0, -2.0, 0.5}, {0.0, 0.0, 0.0, 1.0});
  // 1.0 = 3FF0000000000000, -2.0 = C000000000000000 (IEEE 754, big-endian)
  const std::vector<std::uint8_t> one = {0x3F, 0xF0, 0, 0, 0, 0, 0, 0};
  EXPECT_EQ(std::vector<std::uint8_t>(payload + 8, payload + 16), one);
  EXPECT_EQ(payload[16], 0xC0);
  EXPECT_EQ(std::vector<std::uint8_t>(payload + 56, payload + 64), one);  // w last
  std::uint8_t name[64];
  const std::size_t n = write_name_payload(name, sizeof name, "arm");
  ASSERT_EQ(n, 8u);  // length word (4, NUL included) + "arm\0"
  EXPECT_EQ(std::vector<std::uint8_t>(name, name + 8),
            (std::vector<std::uint8_t>{0, 0, 0, 4, 'a', 'r', 'm', 0}));
  // VRPN refuses a description payload over vrpn_CNAME (100 bytes): names of <= 95 chars.
  std::uint8_t longest[128];
  EXPECT_EQ(write_name_payload(longest, sizeof longest, std::string(95, 'a')), 100u);
  EXPECT_EQ(write_name_payload(longest, sizeof longest, std::string(96, 'a')), 0u);
  std::uint8_t msg[64];
  std::memset(msg, 0xAB, sizeof msg);
  const std::size_t m =
      write_message(msg, sizeof msg, kSenderDescription, 2, WireTime{10, 20}, 7, name, n);
  ASSERT_EQ(m, 32u);             // 24 + 8
  EXPECT_EQ(get_u32(msg), 32u);  // header + payload, no padding counted
  EXPECT_EQ(get_u32(msg + 4), 10u);
  EXPECT_EQ(get_u32(msg + 8), 20u);
  EXPECT_EQ(get_u32(msg + 12), 2u);
  EXPECT_EQ(get_u32(msg + 16), 0xFFFFFFFFu);  // -1
  EXPECT_EQ(get_u32(msg + 20), 7u);
  const std::size_t odd = write_message(msg, sizeof msg, 5, 0, WireTime{}, 0, name, 5);
  EXPECT_EQ(odd, 32u);  // 5 bytes padded to 8
  EXPECT_EQ(get_u32(msg), 29u);
  EXPECT_EQ(msg[29], 0);
  EXPECT_EQ(msg[31], 0);
  EXPECT_EQ(write_message(msg, 31, 5, 0, WireTime{}, 0, name, 5), 0u);  // does not fit
  const WireTime t = wire_time(1'700'000'000'987'654'321);
  EXPECT_EQ(t.sec, 1'700'000'000);
  EXPECT_EQ(t.usec, 987'654);
}

TEST(VrpnWire, DecoderNeverTrustsLengths) {
  std::uint8_t msg[64] = {};
  MessageView v;
  EXPECT_EQ(parse_message(msg, 3, 1024, v), ParseStatus::kNeedMore);
  put_u32(msg, 23);  // below the header
  EXPECT_EQ(parse_message(msg, 64, 1024, v), ParseStatus::kError);
  put_u32(msg, 2000);  // above the limit
  EXPECT_EQ(parse_message(msg, 64, 1024, v), ParseStatus::kError);
  put_u32(msg, 0xFFFFFFFFu);
  EXPECT_EQ(parse_message(msg, 64, 1024, v), ParseStatus::kError);
  put_u32(msg, 29);
  EXPECT_EQ(parse_message(msg, 31, 1024, v), ParseStatus::kNeedMore);  // padded to 32
  ASSERT_EQ(parse_message(msg, 32, 1024, v), ParseStatus::kMessage);
  EXPECT_EQ(v.payload_len, 5u);
  EXPECT_EQ(v.total_bytes, 32u);
  std::string_view name;
  const std::uint8_t bad_len[] = {0, 0, 0, 9, 'a', 'b', 0};
  EXPECT_FALSE(parse_name_payload(bad_len, sizeof bad_len, name));
  const std::uint8_t no_nul[] = {0, 0, 0, 2, 'a', 'b'};
  EXPECT_FALSE(parse_name_payload(no_nul, sizeof no_nul, name));
  const std::uint8_t ok[] = {0, 0, 0, 3, 'a', 'b', 0, 0};
  ASSERT_TRUE(parse_name_payload(ok, sizeof ok, name));
  EXPECT_EQ(name, "ab");
}

TEST(VrpnWire, ConnectionRequestIsHostAndPortAsVrpnChecksIt) {
  std::uint16_t port = 0;
  auto req = [&](const std::string& s) {
    const auto b = bytes_of(s);
    return parse_connection_request(b.data(), b.size(), port);
  };
  EXPECT_TRUE(req(std::string("192.168.1.7 40001") + '\0'));
  EXPECT_EQ(port, 40001);
  EXPECT_TRUE(req("myhost 1024"));
  EXPECT_FALSE(req("myhost 1023"));   // reserved port
  EXPECT_FALSE(req("my-host 4000"));  // VRPN allows letters, digits and dots
  EXPECT_FALSE(req("host 70000"));
  EXPECT_FALSE(req("host"));
  EXPECT_FALSE(req(" 4000"));
  EXPECT_FALSE(req("host 40a0"));
}

std::vector<std::uint8_t> framed(std::int32_t type, std::int32_t sender,
                                 const std::vector<std::uint8_t>& payload) {
  std::vector<std::uint8_t> out(message_bytes(payload.size()));
  write_message(out.data(), out.size(), type, sender, WireTime{}, 0, payload.data(),
                payload.size());
  return out;
}

std::vector<std::uint8_t> name_of(const std::string& s) {
  std::vector<std::uint8_t> p(4 + s.size() + 1);
  write_name_payload(p.data(), p.size(), s);
  return p;
}

bool feed(Session& s, const std::vector<std::uint8_t>& b, SessionActions& a) {
  std::memcpy(s.space(), b.data(), b.size());
  s.commit(b.size());
  return s.process(a);
}

TEST(VrpnSession, CookieThenDescriptionsPingAndUdp) {
  const std::vector<std::string> bodies = {"arm", "hand"};
  Session s(&bodies);
  SessionActions a;
  std::vector<std::uint8_t> cookie(kCookieBytes);
  write_cookie(cookie.data());
  ASSERT_TRUE(feed(s, std::vector<std::uint8_t>(cookie.begin(), cookie.begin() + 10), a));
  EXPECT_FALSE(s.cookie_received());
  ASSERT_TRUE(feed(s, std::vector<std::uint8_t>(cookie.begin() + 10, cookie.end()), a));
  EXPECT_TRUE(s.cookie_received());
  ASSERT_TRUE(feed(s, framed(kSenderDescription, 4, name_of("hand")), a));
  ASSERT_TRUE(feed(s, framed(kTypeDescription, 9, name_of("vrpn_Base ping_message")), a));
  const auto ping = framed(9, 4, {});
  ASSERT_TRUE(feed(s, std::vector<std::uint8_t>(ping.begin(), ping.begin() + 5), a));
  EXPECT_EQ(a.pong_count, 0);  // incomplete
  ASSERT_TRUE(feed(s, std::vector<std::uint8_t>(ping.begin() + 5, ping.end()), a));
  ASSERT_EQ(a.pong_count, 1);
  EXPECT_EQ(a.pongs[0], 1);  // our sender id of "hand"
  ASSERT_TRUE(feed(s, framed(kUdpDescription, 45000, bytes_of(std::string("10.0.0.2") + '\0')), a));
  EXPECT_EQ(a.udp_port, 45000);
  SessionActions b;
  EXPECT_FALSE(feed(s, framed(-9, 0, {}), b));  // unknown system message
  EXPECT_STREQ(s.error(), "unknown system message");
}

TEST(VrpnSession, ABadCookieIsAnError) {
  const std::vector<std::string> bodies = {"arm"};
  Session s(&bodies);
  SessionActions a;
  EXPECT_FALSE(feed(s, bytes_of("GET / HTTP/1.1\r\nHost: x\r\n\r\n"), a));
}

}  // namespace
}  // namespace mocap::publish::vrpn
