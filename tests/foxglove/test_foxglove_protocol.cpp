// Tests of the Foxglove protocol handler (pipeline/foxglove/protocol.h): server texts,
// the Message Data header, subscriptions, and every kind of violation closing the
// connection with a reason while leaving the subscriptions as they were.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "pipeline/foxglove/protocol.h"

namespace mocap::foxglove {
namespace {

using nlohmann::json;

TEST(FoxgloveProtocol, ServerInfoAndAdvertiseFollowTheSpec) {
  const json info = json::parse(server_info_json("mocap", "s1"));
  EXPECT_EQ(info["op"], "serverInfo");
  EXPECT_EQ(info["name"], "mocap");
  EXPECT_TRUE(info["capabilities"].is_array());
  EXPECT_EQ(info["sessionId"], "s1");
  const json adv =
      json::parse(advertise_json({ChannelInfo{7, "/tf", "foxglove.FrameTransforms", "{}"}}));
  EXPECT_EQ(adv["op"], "advertise");
  ASSERT_EQ(adv["channels"].size(), 1u);
  const json& c = adv["channels"][0];
  EXPECT_EQ(c["id"], 7);
  EXPECT_EQ(c["topic"], "/tf");
  EXPECT_EQ(c["encoding"], "json");
  EXPECT_EQ(c["schemaName"], "foxglove.FrameTransforms");
  EXPECT_EQ(c["schemaEncoding"], "jsonschema");
  const json st = json::parse(status_json(StatusLevel::kError, "bad \xff byte"));
  EXPECT_EQ(st["op"], "status");
  EXPECT_EQ(st["level"], 2);
}

TEST(FoxgloveProtocol, MessageDataHeaderIsLittleEndian) {
  const auto h = message_data_header(0x04030201u, 0x0C0B0A0908070605ull);
  const std::array<std::uint8_t, 13> expected{1, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12};
  EXPECT_EQ(h, expected);
  std::uint32_t sub = 0;
  std::uint64_t ts = 0;
  ASSERT_TRUE(parse_message_data_header(h.data(), h.size(), sub, ts));
  EXPECT_EQ(sub, 0x04030201u);
  EXPECT_EQ(ts, 0x0C0B0A0908070605ull);
  EXPECT_FALSE(parse_message_data_header(h.data(), 12, sub, ts));
  auto bad = h;
  bad[0] = 2;
  EXPECT_FALSE(parse_message_data_header(bad.data(), bad.size(), sub, ts));
}

TEST(FoxgloveProtocol, SubscribeAndUnsubscribe) {
  ClientProtocol p({1, 2, 3});
  std::uint32_t sub = 0;
  EXPECT_FALSE(p.subscription_for(1, sub));
  ASSERT_TRUE(p.on_text(
      R"({"op":"subscribe","subscriptions":[{"id":10,"channelId":1},{"id":11,"channelId":3}]})"))
      << p.error();
  ASSERT_TRUE(p.subscription_for(1, sub));
  EXPECT_EQ(sub, 10u);
  ASSERT_TRUE(p.subscription_for(3, sub));
  EXPECT_EQ(sub, 11u);
  EXPECT_FALSE(p.subscription_for(2, sub));
  EXPECT_EQ(p.subscription_count(), 2);
  ASSERT_TRUE(p.on_text(R"({"op":"unsubscribe","subscriptionIds":[10]})")) << p.error();
  EXPECT_FALSE(p.subscription_for(1, sub));
  EXPECT_EQ(p.subscription_count(), 1);
  // A channel may be subscribed again after unsubscribing, with a new or the old id.
  ASSERT_TRUE(p.on_text(R"({"op":"subscribe","subscriptions":[{"id":10,"channelId":1}]})"));
  EXPECT_EQ(p.subscription_count(), 2);
}

struct Violation {
  const char* text;
  const char* reason_part;
};

TEST(FoxgloveProtocol, ViolationsCloseWithAReasonAndChangeNothing) {
  const Violation cases[] = {
      {"not json", "not valid JSON"},
      {"[1,2]", "not a JSON object"},
      {R"({"op":1})", "no string 'op'"},
      {R"({"op":"advertise","channels":[]})", "unsupported op 'advertise'"},
      {R"({"op":"getParameters"})", "unsupported op"},
      {R"({"op":"subscribe"})", "'subscriptions' is not an array"},
      {R"({"op":"subscribe","subscriptions":[{"id":1,"channelId":99}]})",
       "channel 99 is not advertised"},
      {R"({"op":"subscribe","subscriptions":[{"id":5,"channelId":2}]})", "id 5 is already in use"},
      {R"({"op":"subscribe","subscriptions":[{"id":6,"channelId":1}]})", "already subscribed"},
      {R"({"op":"subscribe","subscriptions":[{"id":-1,"channelId":2}]})", "u32"},
      {R"({"op":"subscribe","subscriptions":[{"id":4294967296,"channelId":2}]})", "u32"},
      {R"({"op":"subscribe","subscriptions":[{"id":1.5,"channelId":2}]})", "u32"},
      {R"({"op":"subscribe","subscriptions":[{"id":7,"channelId":2},{"id":7,"channelId":3}]})",
       "already in use"},
      {R"({"op":"unsubscribe","subscriptionIds":[42]})", "unknown subscription id 42"},
      {R"({"op":"unsubscribe","subscriptionIds":["5"]})", "integers"},
      {R"({"op":"subscribe","subscriptions":[[[[[[[[[[]]]]]]]]]]})", "deeper than"},
      {"{\"op\":\"subscribe\xff\"}", "not valid JSON"},
  };
  for (const Violation& v : cases) {
    ClientProtocol p({1, 2, 3});
    ASSERT_TRUE(p.on_text(R"({"op":"subscribe","subscriptions":[{"id":5,"channelId":1}]})"));
    EXPECT_FALSE(p.on_text(v.text)) << v.text;
    EXPECT_NE(p.error().find(v.reason_part), std::string::npos) << v.text << " -> " << p.error();
    EXPECT_EQ(p.error().find('\n'), std::string::npos);
    // The failed message changed nothing: channel 1 still subscribed as 5, 2 and 3 not.
    std::uint32_t sub = 0;
    EXPECT_TRUE(p.subscription_for(1, sub));
    EXPECT_EQ(sub, 5u);
    EXPECT_EQ(p.subscription_count(), 1) << v.text;
  }
}

TEST(FoxgloveProtocol, BinaryFromClientIsAViolation) {
  ClientProtocol p({1});
  EXPECT_FALSE(p.on_binary(5));
  EXPECT_NE(p.error().find("binary"), std::string::npos);
}

TEST(FoxgloveProtocol, JsonDepthIgnoresBracketsInStrings) {
  EXPECT_EQ(json_depth(R"({"a":"[[[[{{{{"})", 8), 1);
  EXPECT_EQ(json_depth(R"({"a":"\"[[[["})", 8), 1);
  EXPECT_EQ(json_depth("[[[]]]", 8), 3);
  EXPECT_GT(json_depth(std::string(100000, '['), 8), 8);
}

}  // namespace
}  // namespace mocap::foxglove
