// Tests of the Foxglove server (pipeline/foxglove/server.h) over 127.0.0.1 with real
// WebSocket clients: the session flow (serverInfo, advertise, subscribe, Message Data),
// refusals (plain HTTP, wrong subprotocol, too many viewers), hostile input ending only
// that connection, and a viewer that never reads: its messages are dropped and counted,
// it is disconnected as stalled, and the other viewer keeps receiving.
#include <gtest/gtest.h>

#include <chrono>
#include <functional>
#include <nlohmann/json.hpp>
#include <thread>

#include "pipeline/foxglove/server.h"
#include "tests/foxglove/ws_test_client.h"

namespace mocap::foxglove {
namespace {

using nlohmann::json;
using test::WsClient;

std::vector<ChannelInfo> test_channels() {
  return {ChannelInfo{1, "/a", "test.A", R"({"type":"object"})"},
          ChannelInfo{2, "/b", "test.B", R"({"type":"object"})"}};
}

std::unique_ptr<Server> start_server(ServerOptions o = {}) {
  o.port = 0;
  auto s = Server::create(o, test_channels());
  EXPECT_TRUE(s.ok()) << (s.ok() ? "" : s.error().message);
  if (!s.ok()) return nullptr;
  auto server = std::move(s.value());
  server->start();
  return server;
}

bool eventually(const std::function<bool()>& condition) {
  for (int i = 0; i < 500; ++i) {
    if (condition()) return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  return false;
}

// Connects, reads serverInfo + advertise, subscribes channel 1 as subscription `sub`.
void open_and_subscribe(WsClient& c, std::uint16_t port, int sub, int receive_buffer = 0) {
  ASSERT_TRUE(c.connect(port, "foxglove.websocket.v1", receive_buffer)) << c.error;
  const auto info = c.read();
  ASSERT_TRUE(info.has_value()) << c.error;
  EXPECT_EQ(json::parse(*info)["op"], "serverInfo");
  const auto adv = c.read();
  ASSERT_TRUE(adv.has_value()) << c.error;
  EXPECT_EQ(json::parse(*adv)["channels"].size(), 2u);
  ASSERT_TRUE(c.send_text(R"({"op":"subscribe","subscriptions":[{"id":)" + std::to_string(sub) +
                          R"(,"channelId":1}]})"));
}

TEST(FoxgloveServer, ListenAddressParsing) {
  ServerOptions o;
  ASSERT_TRUE(parse_listen_address("9000", "--foxglove", o).ok());
  EXPECT_EQ(o.address, "127.0.0.1");
  EXPECT_EQ(o.port, 9000);
  ASSERT_TRUE(parse_listen_address("0.0.0.0:8765", "--foxglove", o).ok());
  EXPECT_EQ(o.address, "0.0.0.0");
  ASSERT_TRUE(parse_listen_address("[::1]:8765", "--foxglove", o).ok());
  EXPECT_EQ(o.address, "::1");
  for (const char* bad : {"", "x", "70000", "host:80", "1.2.3.4:", "1.2.3.4:-1"}) {
    auto r = parse_listen_address(bad, "--foxglove", o);
    ASSERT_FALSE(r.ok()) << bad;
    EXPECT_EQ(r.error().message.rfind("--foxglove", 0), 0u) << r.error().message;
  }
}

TEST(FoxgloveServer, SubscribedViewerReceivesMessageData) {
  auto server = start_server();
  ASSERT_TRUE(server);
  WsClient c;
  open_and_subscribe(c, server->port(), 77);
  ASSERT_TRUE(eventually([&] { return server->has_subscribers(1); }));
  EXPECT_FALSE(server->has_subscribers(2));
  server->broadcast(2, 5, std::make_shared<const std::string>("not subscribed"));
  server->broadcast(1, 123456789, std::make_shared<const std::string>(R"({"x":1})"));
  bool text = true;
  const auto m = c.read(&text);
  ASSERT_TRUE(m.has_value()) << c.error;
  EXPECT_FALSE(text);
  std::uint32_t sub = 0;
  std::uint64_t ts = 0;
  ASSERT_TRUE(parse_message_data_header(reinterpret_cast<const std::uint8_t*>(m->data()), m->size(),
                                        sub, ts));
  EXPECT_EQ(sub, 77u);
  EXPECT_EQ(ts, 123456789u);
  EXPECT_EQ(m->substr(kMessageDataHeaderBytes), R"({"x":1})");
  EXPECT_EQ(server->counters().clients_active, 1);
}

TEST(FoxgloveServer, RefusesPlainHttpWrongSubprotocolAndTooManyViewers) {
  ServerOptions o;
  o.max_clients = 2;
  auto server = start_server(o);
  ASSERT_TRUE(server);
  const std::string answer =
      test::raw_exchange(server->port(), "GET / HTTP/1.1\r\nHost: x\r\n\r\n");
  EXPECT_EQ(answer.rfind("HTTP/1.1 400", 0), 0u) << answer;
  WsClient wrong;
  EXPECT_FALSE(wrong.connect(server->port(), "other.v1"));
  WsClient a, b, c;
  ASSERT_TRUE(a.connect(server->port())) << a.error;
  ASSERT_TRUE(b.connect(server->port())) << b.error;
  EXPECT_FALSE(c.connect(server->port()));
  const std::string upgrade =
      "GET / HTTP/1.1\r\nHost: x\r\nUpgrade: websocket\r\nConnection: Upgrade\r\n"
      "Sec-WebSocket-Key: dGhlIHNhbXBsZSBub25jZQ==\r\nSec-WebSocket-Version: 13\r\n"
      "Sec-WebSocket-Protocol: foxglove.websocket.v1\r\n\r\n";
  const std::string full = test::raw_exchange(server->port(), upgrade);
  EXPECT_EQ(full.rfind("HTTP/1.1 503", 0), 0u) << full;
  EXPECT_EQ(server->counters().clients_refused, 4u);
  a.ws.close(test::websocket::close_code::normal);
  ASSERT_TRUE(eventually([&] { return server->counters().clients_active == 1; }));
  WsClient d;
  EXPECT_TRUE(d.connect(server->port())) << d.error;
}

TEST(FoxgloveServer, IdleConnectionsAreBoundedAndTimedOut) {
  ServerOptions o;
  o.handshake_ms = 300;
  auto server = start_server(o);
  ASSERT_TRUE(server);
  test::asio::io_context ioc;
  std::vector<test::tcp::socket> idle;
  for (int i = 0; i < 20; ++i) {  // connect and never send the HTTP request
    idle.emplace_back(ioc);
    idle.back().connect(
        test::tcp::endpoint(test::asio::ip::make_address("127.0.0.1"), server->port()));
  }
  ASSERT_TRUE(eventually([&] { return server->counters().clients_refused >= 4; }));
  // The handshake deadline closes the idle ones; then viewers get in again.
  ASSERT_TRUE(eventually([&] {
    WsClient c;
    return c.connect(server->port());
  }));
  EXPECT_EQ(server->counters().clients_accepted, 1u);
}

TEST(FoxgloveServer, HostileInputEndsOnlyThatConnection) {
  ServerOptions o;
  o.max_message_bytes = 4096;
  auto server = start_server(o);
  ASSERT_TRUE(server);
  WsClient good;
  open_and_subscribe(good, server->port(), 1);
  const std::vector<std::function<bool(WsClient&)>> attacks = {
      [](WsClient& c) { return c.send_text("{not json"); },
      [](WsClient& c) { return c.send_text(R"({"op":"setParameters","parameters":[]})"); },
      [](WsClient& c) {
        return c.send_text(R"({"op":"subscribe","subscriptions":[{"id":1,"channelId":9}]})");
      },
      [](WsClient& c) { return c.send_binary(std::string("\x01\x00\x00\x00\x00", 5)); },
      [](WsClient& c) { return c.send_text(std::string(10000, ' ')); },
  };
  for (std::size_t i = 0; i < attacks.size(); ++i) {
    WsClient bad;
    ASSERT_TRUE(bad.connect(server->port())) << bad.error;
    ASSERT_TRUE(bad.read().has_value());  // serverInfo
    ASSERT_TRUE(bad.read().has_value());  // advertise
    attacks[i](bad);
    if (i + 1 == attacks.size()) {  // oversized: Beast answers with close code 1009 at once
      EXPECT_FALSE(bad.read().has_value());
      continue;
    }
    const auto status = bad.read();
    ASSERT_TRUE(status.has_value()) << "attack " << i << ": " << bad.error;
    const json s = json::parse(*status);
    EXPECT_EQ(s["op"], "status");
    EXPECT_EQ(s["level"], 2);
    EXPECT_FALSE(bad.read().has_value()) << "attack " << i << " left the connection open";
  }
  // The server counts an error when its session ends, which may follow the close the
  // client has already seen.
  EXPECT_TRUE(eventually([&] { return server->counters().protocol_errors == attacks.size(); }))
      << server->counters().protocol_errors;
  // Raw garbage instead of HTTP.
  EXPECT_EQ(test::raw_exchange(server->port(), std::string(5000, '\x16')).find("101"),
            std::string::npos);
  server->broadcast(1, 1, std::make_shared<const std::string>("still here"));
  const auto m = good.read();
  ASSERT_TRUE(m.has_value()) << good.error;
  EXPECT_EQ(m->substr(kMessageDataHeaderBytes), "still here");
}

TEST(FoxgloveServer, ViewerThatNeverReadsIsDroppedAndOthersKeepReceiving) {
  ServerOptions o;
  o.client_queue_depth = 4;
  o.stall_ms = 300;
  auto server = start_server(o);
  ASSERT_TRUE(server);
  WsClient stalled, good;
  open_and_subscribe(stalled, server->port(), 1, 4096);  // then never reads again
  open_and_subscribe(good, server->port(), 2);
  ASSERT_TRUE(eventually([&] {  // both subscriptions processed (not a sleep: CI is loaded)
    return server->counters().clients_active == 2 && server->subscriber_count(1) == 2;
  }));
  const auto big = std::make_shared<const std::string>(std::string(256 * 1024, 'x'));
  int received = 0;
  for (int i = 0; i < 40; ++i) {
    server->broadcast(1, static_cast<std::uint64_t>(i), big);
    if (good.read().has_value()) ++received;
  }
  EXPECT_EQ(received, 40);  // the reading viewer got every message
  // The stall is counted when it is detected; the session leaves the active set when its
  // socket has closed, a step later on the io thread.
  ASSERT_TRUE(eventually([&] {
    const ServerCounters now = server->counters();
    return now.stalled_clients == 1 && now.clients_active == 1;
  }));
  const ServerCounters c = server->counters();
  EXPECT_GT(c.messages_dropped, 0u);
  EXPECT_EQ(c.clients_active, 1);
}

}  // namespace
}  // namespace mocap::foxglove
