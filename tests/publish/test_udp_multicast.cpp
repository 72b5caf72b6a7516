// UDP multicast on loopback: the publisher sends to a group (IP_MULTICAST_IF 127.0.0.1,
// TTL 1, loop on) and two client UdpReceivers that joined the group on 127.0.0.1 both
// get every datagram (SO_REUSEADDR lets them share the port). Skipped, with the reason,
// only when the kernel refuses multicast on lo. Also: setup errors are one line.
#include <gtest/gtest.h>

#include <chrono>
#include <string>

#include "client/udp_receiver.h"
#include "pipeline/publish/udp_publisher.h"
#include "tests/support/udp_port.h"

namespace mocap::publish {
namespace {

constexpr const char* kGroup = "239.255.77.55";

client::JointsMessage message(std::uint64_t seq) {
  client::JointsMessage m;
  m.sequence = seq;
  m.capture_ns = 1000 + static_cast<std::int64_t>(seq);
  m.publish_ns = 2000 + static_cast<std::int64_t>(seq);
  m.joint_count = 1;
  m.joints[0].type = 1;
  m.joints[0].valid = 1;
  m.joints[0].a[0] = 0.25f * static_cast<float>(seq);
  return m;
}

TEST(UdpMulticast, TwoReceiversInTheGroupGetEveryDatagramOnLoopback) {
  const std::string dest = std::string(kGroup) + ":" + std::to_string(test::free_udp_port());
  auto rx1 = client::UdpReceiver::create(dest, "127.0.0.1");
  if (!rx1.ok() && rx1.error().message.find("join multicast") != std::string::npos) {
    GTEST_SKIP() << "the kernel refuses multicast on lo here: " << rx1.error().message;
  }
  ASSERT_TRUE(rx1.ok()) << rx1.error().message;
  EXPECT_TRUE(rx1->multicast());
  auto rx2 = client::UdpReceiver::create(dest, "127.0.0.1");
  ASSERT_TRUE(rx2.ok()) << rx2.error().message;

  UdpMulticastOptions mc;
  mc.interface = "127.0.0.1";
  auto pub = UdpPublisher::create({dest}, mc);
  ASSERT_TRUE(pub.ok()) << pub.error().message;
  for (std::uint64_t s = 1; s <= 20; ++s)
    ASSERT_EQ(pub->publish(message(s)), mocap::publish::UdpPublisher::Status::kSent);

  for (client::UdpReceiver* rx : {&rx1.value(), &rx2.value()}) {
    const auto until = std::chrono::steady_clock::now() + std::chrono::seconds(2);
    while (rx->counters().accepted < 20 && std::chrono::steady_clock::now() < until)
      rx->wait(std::chrono::milliseconds(10));
    EXPECT_EQ(rx->counters().accepted, 20u);
    EXPECT_EQ(rx->counters().dropped_frames, 0u);
    EXPECT_EQ(rx->latest().sequence, 20u);
    EXPECT_EQ(rx->latest().joints[0].a[0], 5.0f);
  }
}

TEST(UdpMulticast, SetupErrorsAreOneLine) {
  UdpMulticastOptions bad_if;
  bad_if.interface = "not-an-address";
  auto p = UdpPublisher::create({std::string(kGroup) + ":7755"}, bad_if);
  ASSERT_FALSE(p.ok());
  EXPECT_NE(p.error().message.find("multicast interface"), std::string::npos);
  UdpMulticastOptions bad_ttl;
  bad_ttl.ttl = 300;
  EXPECT_FALSE(UdpPublisher::create({std::string(kGroup) + ":7755"}, bad_ttl).ok());
  auto r = client::UdpReceiver::create(std::string(kGroup) + ":0", "1.2.3");
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.error().message.find('\n'), std::string::npos);
  EXPECT_NE(r.error().message.find("multicast interface"), std::string::npos);
}

}  // namespace
}  // namespace mocap::publish
