// Tests of the "foxglove" output of the registry (pipeline/foxglove/foxglove_sink.cpp):
// option checks with one-line errors, and frames published through the seam reaching a
// subscribed WebSocket viewer as /tf, /markers and /joints messages, while publish()
// never waits for the viewer.
#include <gtest/gtest.h>

#include <chrono>
#include <nlohmann/json.hpp>
#include <thread>

#include "pipeline/foxglove/encode.h"
#include "pipeline/publish/output_registry.h"
#include "tests/foxglove/ws_test_client.h"

namespace mocap::publish {
namespace {

using nlohmann::json;

OutputRequest request(std::vector<std::string> values) {
  OutputRequest r;
  r.name = "foxglove";
  r.values = std::move(values);
  r.where = "run.yaml: outputs.foxglove";
  return r;
}

TEST(FoxgloveSink, ChecksItsRequest) {
  const OutputKind* kind = find_output_kind("foxglove");
  ASSERT_NE(kind, nullptr);
  EXPECT_TRUE(kind->check(request({"8765"})).ok());
  EXPECT_TRUE(kind->check(request({"0.0.0.0:8765"})).ok());
  for (const auto& bad :
       std::vector<std::vector<std::string>>{{}, {"a", "b"}, {"99999"}, {"host:1"}}) {
    auto r = kind->check(request(bad));
    ASSERT_FALSE(r.ok());
    EXPECT_EQ(r.error().message.rfind("run.yaml: outputs.foxglove", 0), 0u) << r.error().message;
  }
  OutputRequest opt = request({"8765"});
  opt.options.emplace_back("max_clients", "0");
  auto r = kind->check(opt);
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.error().message.find("max_clients"), std::string::npos) << r.error().message;
  OutputRequest rate = request({"8765"});
  rate.options.emplace_back("max_rate_hz", "0");
  r = kind->check(rate);
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.error().message.find("max_rate_hz"), std::string::npos) << r.error().message;
}

TEST(FoxgloveSink, PublishedFramesReachASubscribedViewer) {
  TargetSet targets;
  targets.bodies.push_back({"torso", {Vec3(0, 0, 0), Vec3(50, 0, 0), Vec3(0, 50, 0)}});
  OutputContext ctx;
  ctx.targets = &targets;
  ctx.frame_rate_hz = 100.0;
  // Port 0: the notice names the port the server got.
  auto created = find_output_kind("foxglove")->create(request({"127.0.0.1:0"}), ctx);
  ASSERT_TRUE(created.ok()) << created.error().message;
  ASSERT_TRUE(created->sink);
  OutputSink& sink = *created->sink;
  EXPECT_STREQ(sink.name(), "foxglove");
  const std::string notice = sink.notice();
  const auto colon = notice.rfind(':');
  ASSERT_NE(colon, std::string::npos) << notice;
  const auto port = static_cast<std::uint16_t>(std::stoi(notice.substr(colon + 1)));

  foxglove::test::WsClient viewer;
  ASSERT_TRUE(viewer.connect(port)) << viewer.error;
  ASSERT_TRUE(viewer.read().has_value());  // serverInfo
  ASSERT_TRUE(viewer.read().has_value());  // advertise
  ASSERT_TRUE(viewer.send_text(
      R"({"op":"subscribe","subscriptions":[{"id":1,"channelId":1},{"id":2,"channelId":2},{"id":3,"channelId":3}]})"));
  std::this_thread::sleep_for(std::chrono::milliseconds(100));  // subscription processed

  FrameResult frame;
  frame.body_count = 1;
  frame.bodies[0].found = 1;
  frame.bodies[0].t_world_body_mm = {100.0, 0.0, 0.0};
  // Frames captured at 200 Hz: the 3D channels go out at most at 50 Hz (max_rate_hz), so
  // frames 0, 4 and 8 of these 9 are sent.
  for (int i = 0; i < 9; ++i) {
    frame.joints.sequence = static_cast<std::uint64_t>(i);
    frame.joints.capture_ns = 1'000'000 + i * 5'000'000LL;
    EXPECT_TRUE(sink.publish(frame));
    std::this_thread::sleep_for(std::chrono::milliseconds(10));  // the worker keeps up
  }
  int tf = 0, markers = 0, joints = 0;
  std::uint64_t first_ts = 0;
  for (int i = 0; i < 9; ++i) {
    const auto m = viewer.read();
    ASSERT_TRUE(m.has_value()) << viewer.error;
    std::uint32_t sub = 0;
    std::uint64_t ts = 0;
    ASSERT_TRUE(foxglove::parse_message_data_header(
        reinterpret_cast<const std::uint8_t*>(m->data()), m->size(), sub, ts));
    if (i == 0) first_ts = ts;
    const json j = json::parse(m->substr(foxglove::kMessageDataHeaderBytes));
    if (sub == 1) {
      ++tf;
      EXPECT_EQ(j["transforms"][0]["child_frame_id"], "torso");
      EXPECT_DOUBLE_EQ(j["transforms"][0]["translation"]["x"].get<double>(), 0.1);
    }
    markers += sub == 2 ? 1 : 0;
    joints += sub == 3 ? 1 : 0;
    EXPECT_GT(ts, 1'000'000'000'000'000'000ull);  // wall clock (after 2001), not monotonic
  }
  EXPECT_EQ(tf, 3);
  EXPECT_EQ(markers, 3);
  EXPECT_EQ(joints, 3);
  // Nothing else was sent: the next message is the one of a frame captured 1 s later.
  frame.joints.capture_ns = 1'000'000 + 1'000'000'000LL;
  EXPECT_TRUE(sink.publish(frame));
  const auto late = viewer.read();
  ASSERT_TRUE(late.has_value()) << viewer.error;
  std::uint32_t sub = 0;
  std::uint64_t late_ts = 0;
  ASSERT_TRUE(foxglove::parse_message_data_header(
      reinterpret_cast<const std::uint8_t*>(late->data()), late->size(), sub, late_ts));
  EXPECT_EQ(late_ts - first_ts, 1'000'000'000u);
  // Every frame reached the encoder (counted after encode() returns, maybe after the
  // viewer got its message).
  for (int i = 0; i < 200 && sink.counters().published < 10u; ++i)
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  EXPECT_EQ(sink.counters().published, 10u);
}

}  // namespace
}  // namespace mocap::publish
