// Design: the output registry without RouDi (a socket path nobody binds, so the result
// never depends on a RouDi running elsewhere on the machine): udp + iceoryx requests
// build a UDP sink and one notice line, the UDP sink delivers FrameResult::joints
// unchanged (publish_ns as stamped by the caller) without allocating, and bad requests
// (unknown output, bad destination, bad flag) fail with one line naming the request.
#include <gtest/gtest.h>
#include <time.h>

#include "client/udp_receiver.h"
#include "pipeline/publish/iceoryx_publisher.h"
#include "pipeline/publish/output_registry.h"
#include "tests/support/alloc_counter.h"
#include "tests/support/test_support.h"

namespace {

using mocap::publish::OutputRequest;

#ifdef MOCAP_CLIENT_HAVE_ICEORYX
TEST(IceoryxPublisher, WithoutRouDiFailsFastWithOneLine) {
  mocap::test::TempDir dir("no_roudi");
  const std::string path = dir.file("roudi");  // nothing bound there
  auto p = mocap::publish::IceoryxPublisher::create("mocap_test_no_roudi", path.c_str());
  ASSERT_FALSE(p.ok());
  EXPECT_EQ(p.error().message, "iceoryx: RouDi (iox-roudi) not running; publishing over UDP only");
}
#endif

TEST(OutputRegistry, UdpAndIceoryxWithoutRouDiGiveOneSinkAndOneNotice) {
  auto rx = mocap::client::UdpReceiver::create("127.0.0.1:0");
  ASSERT_TRUE(rx.ok());
  mocap::test::TempDir dir("no_roudi");
  const std::string path = dir.file("roudi");
  std::vector<OutputRequest> req = {
      {"udp", {"127.0.0.1:" + std::to_string(rx->port())}, "test: outputs.udp", {}},
      {"iceoryx", {"true"}, "test: outputs.iceoryx", {{"roudi_socket", path}}}};
  auto outs = mocap::publish::create_outputs(req, {});
  ASSERT_TRUE(outs.ok()) << outs.error().message;
  ASSERT_EQ(outs->sinks.size(), 1u);
  EXPECT_STREQ(outs->sinks[0]->name(), "udp");
  ASSERT_EQ(outs->notices.size(), 1u);
#ifdef MOCAP_CLIENT_HAVE_ICEORYX
  EXPECT_EQ(outs->notices[0], "iceoryx: RouDi (iox-roudi) not running; publishing over UDP only");
#else
  EXPECT_EQ(outs->notices[0], "iceoryx: not built in; publishing over UDP only");
#endif

  auto frame = std::make_unique<mocap::publish::FrameResult>();
  frame->joints.joint_count = 1;
  frame->joints.joints[0].valid = 1;
  frame->joints.joints[0].a[0] = 0.5f;
  frame->joints.capture_ns = 1000;
  frame->joints.publish_ns = 123456789;
  mocap::publish::OutputSink& udp = *outs->sinks[0];
  {
    mocap::test::AllocationScope scope;
    for (std::uint64_t s = 1; s <= 20; ++s) {
      frame->joints.sequence = s;
      EXPECT_TRUE(udp.publish(*frame));
      rx->poll();
    }
    EXPECT_EQ(scope.count(), 0u);
  }
  for (int i = 0; i < 400 && rx->counters().datagrams < 20; ++i) {
    rx->wait(std::chrono::milliseconds(5));
  }
  EXPECT_EQ(udp.counters().published, 20u);
  EXPECT_EQ(udp.counters().failures, 0u);
  ASSERT_TRUE(rx->has_message());
  EXPECT_EQ(rx->latest().sequence, 20u);
  EXPECT_EQ(rx->latest().publish_ns, 123456789);
  EXPECT_EQ(rx->latest().capture_ns, 1000);
  EXPECT_FLOAT_EQ(rx->latest().joints[0].a[0], 0.5f);
}

// No listener on the destination is not a failure: every frame is published and the
// refusals (ICMP port unreachable on loopback) are counted as no_listener.
TEST(OutputRegistry, UdpWithoutListenerPublishesEveryFrame) {
  std::uint16_t port = 0;
  {
    auto gone = mocap::client::UdpReceiver::create("127.0.0.1:0");  // a port, then closed
    ASSERT_TRUE(gone.ok());
    port = gone->port();
  }
  std::vector<OutputRequest> req = {
      {"udp", {"127.0.0.1:" + std::to_string(port)}, "test: outputs.udp", {}}};
  auto outs = mocap::publish::create_outputs(req, {});
  ASSERT_TRUE(outs.ok()) << outs.error().message;
  ASSERT_EQ(outs->sinks.size(), 1u);
  auto frame = std::make_unique<mocap::publish::FrameResult>();
  frame->joints.joint_count = 1;
  for (std::uint64_t s = 1; s <= 30; ++s) {
    frame->joints.sequence = s;
    EXPECT_TRUE(outs->sinks[0]->publish(*frame)) << s;
  }
  const auto c = outs->sinks[0]->counters();
  EXPECT_EQ(c.published, 30u);
  EXPECT_EQ(c.failures, 0u);
  EXPECT_GT(c.no_listener, 0u);
}

TEST(OutputRegistry, DisabledOutputsBuildNothing) {
  std::vector<OutputRequest> req = {{"udp", {}, "t: outputs.udp", {}},
                                    {"iceoryx", {"false"}, "t: outputs.iceoryx", {}}};
  auto outs = mocap::publish::create_outputs(req, {});
  ASSERT_TRUE(outs.ok());
  EXPECT_TRUE(outs->sinks.empty());
  EXPECT_TRUE(outs->notices.empty());
}

TEST(OutputRegistry, BadRequestsFailWithOneLine) {
  auto check = [](OutputRequest r) { return mocap::publish::check_outputs({std::move(r)}); };
  auto e = check({"nosuch", {"true"}, "run.yaml: outputs.nosuch (line 7)", {}});
  ASSERT_FALSE(e.ok());
  EXPECT_EQ(e.error().message.rfind("run.yaml: outputs.nosuch (line 7): unknown output 'nosuch' "
                                    "(known: udp, iceoryx",
                                    0),
            0u)
      << e.error().message;
  e = check({"udp", {"127.0.0.1:abc"}, "run.yaml: outputs.udp", {}});
  ASSERT_FALSE(e.ok());
  EXPECT_EQ(e.error().message,
            "run.yaml: outputs.udp: '127.0.0.1:abc': expected HOST:PORT with a port in 1..65535");
  e = check({"iceoryx", {"maybe"}, "run.yaml: outputs.iceoryx", {}});
  ASSERT_FALSE(e.ok());
  EXPECT_EQ(e.error().message, "run.yaml: outputs.iceoryx: expected true or false, got 'maybe'");
  e = check({"udp", {"h:1"}, "--udp", {{"multicast_ttl", "300"}}});
  ASSERT_FALSE(e.ok());
  EXPECT_EQ(e.error().message, "--udp: multicast ttl: must be in 0..255, got '300'");
  e = check({"udp", {"h:1"}, "run.yaml: outputs.udp", {{"multicast_tll", "3"}}});
  ASSERT_FALSE(e.ok());
  EXPECT_EQ(e.error().message,
            "run.yaml: outputs.udp: multicast_tll: unknown option (known: "
            "multicast_if multicast_ttl versions leads_ms)");
  e = check({"ros2", {"true"}, "run.yaml: outputs.ros2", {{"domain_id", "x"}}});
  ASSERT_FALSE(e.ok());
  EXPECT_EQ(e.error().message,
            "run.yaml: outputs.ros2: domain_id: expected an integer in 0..232, got 'x'");
  for (const auto& m : {e.error().message}) EXPECT_EQ(m.find('\n'), std::string::npos);
}

}  // namespace
