// Design: the per-frame aggregate without RouDi (a socket path nobody binds, so the
// result never depends on a RouDi running elsewhere on the machine): setup returns at
// once with the one-line notice, UDP still works, publish_ns is stamped, 0 allocations.
#include <gtest/gtest.h>
#include <time.h>

#include "client/udp_receiver.h"
#include "pipeline/publish/publishers.h"
#include "tests/support/alloc_counter.h"
#include "tests/support/test_support.h"

namespace {

using mocap::client::JointsMessage;

std::int64_t now_ns() {
  timespec ts{};
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return static_cast<std::int64_t>(ts.tv_sec) * 1'000'000'000 + ts.tv_nsec;
}

#ifdef MOCAP_CLIENT_HAVE_ICEORYX
TEST(IceoryxPublisher, WithoutRouDiFailsFastWithOneLine) {
  mocap::test::TempDir dir("no_roudi");
  const std::string path = dir.file("roudi");  // nothing bound there
  auto p = mocap::publish::IceoryxPublisher::create("mocap_test_no_roudi", path.c_str());
  ASSERT_FALSE(p.ok());
  EXPECT_EQ(p.error().message, "iceoryx: RouDi (iox-roudi) not running; publishing over UDP only");
}
#endif

TEST(Publishers, FallsBackToUdpWithOneNotice) {
  auto rx = mocap::client::UdpReceiver::create("127.0.0.1:0");
  ASSERT_TRUE(rx.ok());
  mocap::test::TempDir dir("no_roudi");
  const std::string path = dir.file("roudi");
  mocap::publish::PublishersConfig cfg;
  cfg.udp_destinations = {"127.0.0.1:" + std::to_string(rx->port())};
  cfg.iceoryx = true;
  cfg.roudi_socket_path = path.c_str();
  auto pubs = mocap::publish::Publishers::create(cfg);
  ASSERT_TRUE(pubs.ok()) << pubs.error().message;
  EXPECT_FALSE(pubs->iceoryx_active());
#ifdef MOCAP_CLIENT_HAVE_ICEORYX
  EXPECT_EQ(pubs->notice(), "iceoryx: RouDi (iox-roudi) not running; publishing over UDP only");
#else
  EXPECT_EQ(pubs->notice(), "iceoryx: not built in; publishing over UDP only");
#endif

  JointsMessage m;
  m.joint_count = 1;
  m.joints[0].valid = 1;
  m.joints[0].a[0] = 0.5f;
  const std::int64_t before = now_ns();
  std::uint64_t published = 0;
  {
    mocap::test::AllocationScope scope;
    for (std::uint64_t s = 1; s <= 20; ++s) {
      m.sequence = s;
      m.capture_ns = before;
      if (pubs->publish(m)) ++published;
      rx->poll();
    }
    EXPECT_EQ(scope.count(), 0u);
  }
  for (int i = 0; i < 400 && rx->counters().datagrams < published; ++i) {
    rx->wait(std::chrono::milliseconds(5));
  }
  EXPECT_EQ(published, 20u);
  EXPECT_EQ(pubs->frames(), 20u);
  ASSERT_TRUE(rx->has_message());
  EXPECT_EQ(rx->latest().sequence, 20u);
  EXPECT_GE(rx->latest().publish_ns, before);
  EXPECT_LE(rx->latest().publish_ns, now_ns());
  EXPECT_EQ(rx->latest().capture_ns, before);
}

TEST(Publishers, CallerStampedPublishTimeIsSentUnchanged) {
  auto rx = mocap::client::UdpReceiver::create("127.0.0.1:0");
  ASSERT_TRUE(rx.ok());
  mocap::publish::PublishersConfig cfg;
  cfg.udp_destinations = {"127.0.0.1:" + std::to_string(rx->port())};
  cfg.iceoryx = false;
  cfg.stamp_publish_ns = false;
  auto pubs = mocap::publish::Publishers::create(cfg);
  ASSERT_TRUE(pubs.ok());
  JointsMessage m;
  m.sequence = 3;
  m.publish_ns = 123456789;
  ASSERT_TRUE(pubs->publish(m));
  for (int i = 0; i < 400 && !rx->has_message(); ++i) rx->wait(std::chrono::milliseconds(5));
  ASSERT_TRUE(rx->has_message());
  EXPECT_EQ(rx->latest().publish_ns, 123456789);
}

TEST(Publishers, IceoryxDisabledHasNoNoticeAndBadDestinationFails) {
  mocap::publish::PublishersConfig cfg;
  cfg.iceoryx = false;
  auto pubs = mocap::publish::Publishers::create(cfg);
  ASSERT_TRUE(pubs.ok());
  EXPECT_TRUE(pubs->notice().empty());
  EXPECT_FALSE(pubs->iceoryx_active());
  cfg.udp_destinations = {"127.0.0.1:abc"};
  auto bad = mocap::publish::Publishers::create(cfg);
  ASSERT_FALSE(bad.ok());
  EXPECT_EQ(bad.error().message, "udp publisher: '127.0.0.1:abc': port must be 0..65535");
}

}  // namespace
