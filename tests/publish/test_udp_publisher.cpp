// Design: UdpPublisher -> UdpReceiver over 127.0.0.1 (ephemeral ports): messages arrive
// intact at every destination, sequence gaps are counted, a destination nobody listens
// on never makes publish() fatal, setup errors are one line, and publishing allocates
// nothing. Single-threaded: the kernel socket buffers decouple the two ends.
#include <gtest/gtest.h>

#include "client/udp_receiver.h"
#include "pipeline/publish/udp_publisher.h"
#include "tests/support/alloc_counter.h"

namespace {

using mocap::client::JointsMessage;
using mocap::client::UdpReceiver;
using mocap::publish::UdpPublisher;

JointsMessage make_message(std::uint64_t seq) {
  JointsMessage m;
  m.sequence = seq;
  m.capture_ns = static_cast<std::int64_t>(seq) * 10'000'000;
  m.publish_ns = m.capture_ns + 5'000'000;
  m.flags = mocap::client::kFlagAllBodiesFound;
  m.joint_count = 5;
  for (std::uint16_t j = 0; j < 5; ++j) {
    m.joints[j].index = j;
    m.joints[j].type = static_cast<std::uint8_t>(j % 2);
    m.joints[j].valid = 1;
    m.joints[j].a[0] = 0.01f * static_cast<float>(seq) + 0.1f * static_cast<float>(j);
  }
  return m;
}

UdpReceiver receiver() {
  auto r = UdpReceiver::create("127.0.0.1:0");
  EXPECT_TRUE(r.ok());
  return std::move(r.value());
}

std::string loopback(const UdpReceiver& r) { return "127.0.0.1:" + std::to_string(r.port()); }

void drain(UdpReceiver& rx, std::uint64_t expected_datagrams) {
  for (int i = 0; i < 400 && rx.counters().datagrams < expected_datagrams; ++i) {
    rx.wait(std::chrono::milliseconds(5));
  }
}

TEST(UdpPublisher, LoopbackToTwoReceiversWithGaps) {
  UdpReceiver a = receiver();
  UdpReceiver b = receiver();
  auto pub = UdpPublisher::create({loopback(a), loopback(b)});
  ASSERT_TRUE(pub.ok()) << pub.error().message;
  EXPECT_EQ(pub->destination_count(), 2u);
  std::uint64_t sent = 0;
  for (std::uint64_t seq = 1; seq <= 100; ++seq) {
    if (seq % 10 == 0) continue;  // the pipeline dropped every tenth frame
    ASSERT_EQ(pub->publish(make_message(seq)), UdpPublisher::Status::kSent);
    ++sent;
    if (sent % 16 == 0) {  // keep the receive buffers shallow
      a.poll();
      b.poll();
    }
  }
  drain(a, sent);
  drain(b, sent);
  for (UdpReceiver* rx : {&a, &b}) {
    EXPECT_EQ(rx->counters().accepted, sent);
    EXPECT_EQ(rx->counters().dropped_frames, 9u);  // 10, 20, ..., 90 (100 was the last)
    EXPECT_EQ(rx->counters().rejected_total(), 0u);
    EXPECT_EQ(rx->latest().sequence, 99u);
    const JointsMessage want = make_message(99);
    for (int j = 0; j < 5; ++j) EXPECT_EQ(rx->latest().joints[j].a[0], want.joints[j].a[0]);
  }
  EXPECT_EQ(pub->counters().messages, sent);
  EXPECT_EQ(pub->counters().datagrams_sent, 2 * sent);
}

TEST(UdpPublisher, NobodyListeningIsNeverFatal) {
  std::uint16_t port = 0;
  {
    UdpReceiver gone = receiver();  // take a free port, then close it
    port = gone.port();
  }
  auto pub = UdpPublisher::create({"127.0.0.1:" + std::to_string(port)});
  ASSERT_TRUE(pub.ok());
  for (std::uint64_t s = 0; s < 50; ++s) pub->publish(make_message(s));
  const auto& c = pub->counters();
  EXPECT_EQ(c.messages, 50u);
  // Every datagram is sent: the ICMP port unreachable of one datagram is reported on the
  // next sendto(), which is then repeated once.
  EXPECT_EQ(c.datagrams_sent, 50u);
  EXPECT_GT(c.no_listener, 0u) << "loopback reports the closed port";
  EXPECT_EQ(c.refused + c.would_block + c.other_errors, 0u);
}

TEST(UdpPublisher, TooManyJointsIsCountedNotSent) {
  UdpReceiver rx = receiver();
  auto pub = UdpPublisher::create({loopback(rx)});
  ASSERT_TRUE(pub.ok());
  JointsMessage m = make_message(1);
  m.joint_count = mocap::client::kMaxJoints + 1;
  EXPECT_EQ(pub->publish(m), UdpPublisher::Status::kFailed);
  EXPECT_EQ(pub->counters().encode_failures, 1u);
  EXPECT_EQ(pub->counters().datagrams_sent, 0u);
}

TEST(UdpPublisher, PublishAndReceiveAllocateNothing) {
  UdpReceiver rx = receiver();
  auto pub = UdpPublisher::create({loopback(rx)});
  ASSERT_TRUE(pub.ok());
  const JointsMessage m = make_message(7);
  mocap::test::AllocationScope scope;
  for (int i = 0; i < 200; ++i) {
    pub->publish(m);
    rx.poll();
  }
  EXPECT_EQ(scope.count(), 0u);
  EXPECT_GT(rx.counters().datagrams, 0u);
}

TEST(UdpPublisher, EachDestinationGetsItsDatagramVersion) {
  UdpReceiver v1 = receiver();
  UdpReceiver v2 = receiver();
  auto pub = UdpPublisher::create({loopback(v1), loopback(v2)}, {}, {1, 2});
  ASSERT_TRUE(pub.ok()) << pub.error().message;
  JointsMessage m = make_message(7);
  m.quality[2].solved_by = 2;
  m.quality[2].sd_rad[0] = 0.004f;
  m.rates[2].valid = 1;
  m.rates[2].rate_rad_s[0] = -1.25f;
  m.rates[2].sd_rad_s[0] = 0.03f;
  ASSERT_EQ(pub->publish(m), UdpPublisher::Status::kSent);
  drain(v1, 1);
  drain(v2, 1);
  ASSERT_EQ(v1.counters().accepted, 1u);
  ASSERT_EQ(v2.counters().accepted, 1u);
  EXPECT_EQ(v1.latest_version(), 1);
  EXPECT_EQ(v1.latest().rates[2].valid, 0);  // version 1 carries no rates
  EXPECT_EQ(v2.latest_version(), 2);
  EXPECT_EQ(v2.latest().quality[2].solved_by, 2);
  EXPECT_EQ(v2.latest().rates[2].valid, 1);
  EXPECT_EQ(v2.latest().rates[2].rate_rad_s[0], -1.25f);
  EXPECT_EQ(v2.latest().rates[2].sd_rad_s[0], 0.03f);
  for (int j = 0; j < 5; ++j) EXPECT_EQ(v2.latest().joints[j].a[0], m.joints[j].a[0]);
  // Setup: one version per destination, each 1 or 2.
  EXPECT_EQ(UdpPublisher::create({loopback(v1)}, {}, {1, 2}).error().message,
            "udp publisher: versions: one per destination");
  EXPECT_EQ(UdpPublisher::create({loopback(v1)}, {}, {3}).error().message,
            "udp publisher: version 3: must be 1 or 2");
}

TEST(UdpPublisher, SetupErrorsAreOneLine) {
  auto p = UdpPublisher::create({"127.0.0.1:9000", "localhost"});
  ASSERT_FALSE(p.ok());
  EXPECT_EQ(p.error().message, "udp publisher: 'localhost': expected HOST:PORT");
  p = UdpPublisher::create({"127.0.0.1:0"});
  ASSERT_FALSE(p.ok());
  EXPECT_EQ(p.error().message, "udp publisher: '127.0.0.1:0': port 0 is not a destination");
  p = UdpPublisher::create({"no.such.host.invalid:9000"});
  ASSERT_FALSE(p.ok());
  EXPECT_EQ(
      p.error().message.rfind("udp publisher: 'no.such.host.invalid:9000': cannot resolve", 0), 0u)
      << p.error().message;
  EXPECT_TRUE(UdpPublisher::create({}).ok());  // no destinations: a valid, silent publisher
}

}  // namespace
