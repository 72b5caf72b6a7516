// Tests of the one "[ADDRESS:]PORT" parser (core/listen_address.h): the default address,
// IPv4 and bracketed IPv6 where allowed, every malformed value a one-line error naming the
// key, no name lookup.
#include <gtest/gtest.h>

#include "core/listen_address.h"

namespace mocap {
namespace {

TEST(ListenAddress, DefaultsIpv4AndIpv6) {
  auto a = parse_listen_address("3883", "--vrpn", "127.0.0.1", IpFamilies::kIpv4);
  ASSERT_TRUE(a.ok());
  EXPECT_EQ(a->address, "127.0.0.1");
  EXPECT_EQ(a->port, 3883);
  a = parse_listen_address("0.0.0.0:0", "--vrpn", "127.0.0.1", IpFamilies::kIpv4);
  ASSERT_TRUE(a.ok());
  EXPECT_EQ(a->address, "0.0.0.0");
  EXPECT_EQ(a->port, 0);
  a = parse_listen_address("[::1]:8765", "--foxglove", "127.0.0.1", IpFamilies::kIpv4AndIpv6);
  ASSERT_TRUE(a.ok());
  EXPECT_EQ(a->address, "::1");
  EXPECT_FALSE(parse_listen_address("[::1]:8765", "--vrpn", "127.0.0.1", IpFamilies::kIpv4).ok());
}

TEST(ListenAddress, MalformedValuesAreOneLineNamingTheKey) {
  for (const char* bad : {"", "x", "70000", "localhost:80", "1.2.3.4:", "1.2.3.4:-1", ":80",
                          "1.2.3.4:123456", "1.2.3:80"}) {
    auto r = parse_listen_address(bad, "run.yaml: outputs.vrpn", "127.0.0.1", IpFamilies::kIpv4);
    ASSERT_FALSE(r.ok()) << bad;
    EXPECT_EQ(r.error().message.rfind("run.yaml: outputs.vrpn: '", 0), 0u) << r.error().message;
    EXPECT_EQ(r.error().message.find('\n'), std::string::npos);
  }
}

}  // namespace
}  // namespace mocap
