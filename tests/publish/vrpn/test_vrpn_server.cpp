// The VRPN server (pipeline/publish/vrpn/vrpn_server.h) against the independent test
// client (vrpn_test_client.h) over 127.0.0.1, the server driven by the test thread:
// descriptions and reports decoded by the client equal the hand-made FrameResult (metres,
// x,y,z,w, velocity, system-clock time); the UDP connection request (server connects
// back) with reports by TCP and by UDP; ping -> pong; the client limit; a client that
// never reads (drops counted, then disconnected, server calls never block); a flooding
// client, garbage and a bad cookie (that client disconnected, counted; others served).
#include <gtest/gtest.h>
#include <time.h>

#include <cmath>

#include "pipeline/publish/vrpn/vrpn_server.h"
#include "tests/publish/vrpn/vrpn_test_client.h"

namespace mocap::publish::vrpn {
namespace {

using test::vrpn_client::Client;

std::int64_t mono_now() {
  timespec ts{};
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return std::int64_t{ts.tv_sec} * 1'000'000'000 + ts.tv_nsec;
}

constexpr std::int64_t kOffsetNs = 1'700'000'000'123'456'789;  // "system clock - monotonic"

FrameResult two_body_frame(std::int64_t capture_ns) {
  FrameResult f;
  f.joints.capture_ns = capture_ns;
  f.body_count = 2;
  ResultBody& arm = f.bodies[0];
  arm.found = 1;
  const double n = std::sqrt(0.9 * 0.9 + 0.1 * 0.1 + 0.3 * 0.3 + 0.2 * 0.2);
  arm.q_world_body = {0.9 / n, 0.1 / n, -0.3 / n, 0.2 / n};
  arm.t_world_body_mm = {123.25, -456.5, 789.125};
  arm.velocity_valid = 1;
  arm.v_world_mm_s = {100.0f, -250.0f, 12.5f};
  arm.w_world_rad_s = {0.5f, -1.0f, 2.0f};
  ResultBody& hand = f.bodies[1];
  hand.found = 1;
  hand.t_world_body_mm = {1.0, 2.0, 3.0};
  return f;
}

struct Fixture {
  explicit Fixture(ServerOptions o = {},
                   std::vector<std::string> bodies = {"arm", "hand", "head"}) {
    o.port = 0;
    n_bodies = bodies.size();
    auto s = Server::create(o, std::move(bodies));
    EXPECT_TRUE(s) << (s ? "" : s.error().message);
    if (s) server = std::move(*s);
  }
  void poll() { server->poll(mono_now()); }
  std::function<void()> driver() {
    return [this] { poll(); };
  }
  // Connected, cookies exchanged, descriptions read.
  bool connect(Client& c) {
    c.on_wait = driver();
    if (!c.connect_tcp(server->port())) return false;
    c.send_cookie();
    c.pump(100);
    return c.cookie_ok && c.senders.size() == n_bodies && c.types.size() == 4;
  }
  std::unique_ptr<Server> server;
  std::size_t n_bodies = 0;
};

TEST(VrpnServer, DirectTcpClientGetsDescriptionsAndExactReports) {
  ServerOptions o;
  o.frame_period_s = 0.01;
  Fixture fx(o);
  Client c;
  ASSERT_TRUE(fx.connect(c));
  EXPECT_EQ(c.server_cookie, "vrpn: ver. 07.38");
  EXPECT_EQ(c.senders.at(0), "arm");
  EXPECT_EQ(c.senders.at(2), "head");
  const std::int64_t capture = 5'000'000'000'123'456;  // CLOCK_MONOTONIC ns
  const FrameResult f = two_body_frame(capture);
  fx.server->send_frame(f, kOffsetNs, mono_now());
  c.pump(100);
  ASSERT_EQ(c.protocol_errors, 0);
  ASSERT_EQ(c.reports.size(), 3u);  // arm Pos_Quat + Velocity, hand Pos_Quat; head not found
  const std::int64_t t = capture + kOffsetNs;
  for (const auto& r : c.reports) {
    EXPECT_EQ(r.sec, static_cast<std::int32_t>(t / 1'000'000'000));
    EXPECT_EQ(r.usec, static_cast<std::int32_t>(t % 1'000'000'000 / 1000));
    EXPECT_EQ(r.sensor, 0);
    EXPECT_FALSE(r.via_udp);
  }
  const auto& arm = c.reports[0];
  ASSERT_EQ(arm.body, "arm");
  ASSERT_EQ(arm.type, "vrpn_Tracker Pos_Quat");
  const ResultBody& b = f.bodies[0];
  for (int i = 0; i < 3; ++i) EXPECT_EQ(arm.pos[i], b.t_world_body_mm[i] / 1000.0);
  EXPECT_EQ(arm.quat[0], b.q_world_body[1]);  // x
  EXPECT_EQ(arm.quat[1], b.q_world_body[2]);  // y
  EXPECT_EQ(arm.quat[2], b.q_world_body[3]);  // z
  EXPECT_EQ(arm.quat[3], b.q_world_body[0]);  // w
  const auto& vel = c.reports[1];
  ASSERT_EQ(vel.body, "arm");
  ASSERT_EQ(vel.type, "vrpn_Tracker Velocity");
  for (int i = 0; i < 3; ++i)
    EXPECT_FLOAT_EQ(static_cast<float>(vel.vel[i] * 1000.0), b.v_world_mm_s[i]);
  EXPECT_EQ(vel.dt, 0.01);
  // vel_quat = rotation of w over dt: axis w/|w|, angle |w| dt (x, y, z, w).
  const double w[3] = {0.5, -1.0, 2.0};
  const double rate = std::sqrt(0.25 + 1.0 + 4.0);
  for (int i = 0; i < 3; ++i)
    EXPECT_NEAR(vel.vel_quat[i], w[i] / rate * std::sin(rate * 0.01 / 2), 1e-12);
  EXPECT_NEAR(vel.vel_quat[3], std::cos(rate * 0.01 / 2), 1e-12);
  EXPECT_EQ(c.reports[2].body, "hand");
  EXPECT_EQ(c.reports[2].pos[2], 0.003);
  EXPECT_EQ(fx.server->counters().reports_sent, 3u);
  EXPECT_EQ(fx.server->counters().clients_active, 1);
}

TEST(VrpnServer, UdpConnectionRequestConnectsBackThenUdpReportsOnRequest) {
  Fixture fx;
  Client c;
  c.on_wait = fx.driver();
  ASSERT_TRUE(c.request_connect_back(fx.server->port()));
  c.send_cookie("vrpn: ver. 07.31");  // another 07 minor version
  c.pump(100);
  ASSERT_TRUE(c.cookie_ok);
  EXPECT_EQ(fx.server->counters().connect_backs, 1u);
  fx.server->send_frame(two_body_frame(1'000'000'000), kOffsetNs, mono_now());
  c.pump(100);
  ASSERT_EQ(c.reports.size(), 3u);
  EXPECT_FALSE(c.reports[0].via_udp);
  ASSERT_TRUE(c.ask_udp());  // vrpn_CONNECTION_UDP_DESCRIPTION
  c.pump(50);
  fx.server->send_frame(two_body_frame(2'000'000'000), kOffsetNs, mono_now());
  c.pump(100);
  ASSERT_EQ(c.reports.size(), 6u);
  EXPECT_TRUE(c.reports[3].via_udp);
  EXPECT_EQ(c.reports[5].body, "hand");
  EXPECT_EQ(c.protocol_errors, 0);
  // VRPN repeats its request every 2 s until connected: no second connection for it.
  const std::string again = "127.0.0.1 " + std::to_string(c.listen_port());
  c.send_datagram(fx.server->port(), again.c_str(), again.size() + 1);
  c.send_datagram(fx.server->port(), "bad host! 1", 12);
  fx.poll();
  c.pump(20);
  EXPECT_EQ(fx.server->counters().bad_requests, 1u);
  EXPECT_EQ(fx.server->counters().connect_backs, 1u);
}

TEST(VrpnServer, PingFromANamedSenderGetsAPong) {
  Fixture fx;
  Client c;
  ASSERT_TRUE(fx.connect(c));
  c.send_raw(Client::message(-1, 7, Client::name_payload("hand")));
  c.send_raw(Client::message(-2, 3, Client::name_payload("vrpn_Base ping_message")));
  c.send_raw(Client::message(3, 7, {}));  // ping from our "hand"
  c.pump(100);
  ASSERT_EQ(c.others.size(), 1u);
  EXPECT_EQ(c.others[0].first, "hand");
  EXPECT_EQ(c.others[0].second, "vrpn_Base pong_message");
  EXPECT_EQ(fx.server->counters().pongs_sent, 1u);
  EXPECT_EQ(c.protocol_errors, 0);
}

TEST(VrpnServer, ClientsBeyondTheLimitAreRefusedAndCounted) {
  ServerOptions o;
  o.max_clients = 2;
  Fixture fx(o);
  Client a, b, extra;
  ASSERT_TRUE(fx.connect(a));
  ASSERT_TRUE(fx.connect(b));
  extra.on_wait = fx.driver();
  ASSERT_TRUE(extra.connect_tcp(fx.server->port()));
  EXPECT_FALSE(extra.pump(200));  // closed by the server
  EXPECT_EQ(fx.server->counters().clients_refused, 1u);
  EXPECT_EQ(fx.server->counters().clients_active, 2);
  fx.server->send_frame(two_body_frame(1), 0, mono_now());
  a.pump(50);
  EXPECT_EQ(a.reports.size(), 3u);
}

TEST(VrpnServer, AClientThatNeverReadsLosesFramesThenIsDroppedOthersServed) {
  ServerOptions o;
  o.client_buffer_bytes = 16 * 1024;
  o.stall_ms = 200;
  std::vector<std::string> names;
  FrameResult f = two_body_frame(1);
  f.body_count = kMaxResultBodies;  // 32 bodies with velocities: 5.9 KB per frame
  for (int b = 0; b < kMaxResultBodies; ++b) {
    names.push_back("body" + std::to_string(b));
    f.bodies[static_cast<std::size_t>(b)] = f.bodies[0];
  }
  Fixture fx(o, names);
  Client idle, good;
  ASSERT_TRUE(fx.connect(idle));
  ASSERT_TRUE(fx.connect(good));
  good.on_wait = nullptr;
  const auto t0 = std::chrono::steady_clock::now();
  int frames = 0;
  while (fx.server->counters().stalled == 0 &&
         std::chrono::steady_clock::now() - t0 < std::chrono::seconds(20)) {
    fx.poll();
    fx.server->send_frame(f, 0, mono_now());  // returns at once: never blocks on `idle`
    ++frames;
    good.pump(0);  // `good` reads, `idle` never does
  }
  const ServerCounters c = fx.server->counters();
  EXPECT_GT(c.frames_dropped, 0u);
  EXPECT_EQ(c.stalled, 1u);
  EXPECT_EQ(c.clients_active, 1);
  good.pump(100);
  EXPECT_EQ(good.reports.size(), static_cast<std::size_t>(frames) * 2 * kMaxResultBodies);
  EXPECT_EQ(good.protocol_errors, 0);
}

TEST(VrpnServer, FloodGarbageAndBadCookiesEndOnlyThatClient) {
  Fixture fx;
  Client good;
  ASSERT_TRUE(fx.connect(good));
  {  // a flood of well-formed messages
    Client flood;
    ASSERT_TRUE(fx.connect(flood));
    const std::vector<std::uint8_t> m = Client::message(0, 0, std::vector<std::uint8_t>(64, 1));
    std::vector<std::uint8_t> burst;
    for (int i = 0; i < 1000; ++i) burst.insert(burst.end(), m.begin(), m.end());
    for (int i = 0; i < 4; ++i) flood.send_raw(burst);
    EXPECT_FALSE(flood.pump(300));
    EXPECT_EQ(fx.server->counters().flooding, 1u);
  }
  {  // garbage after the cookie: a length word out of bounds
    Client junk;
    ASSERT_TRUE(fx.connect(junk));
    junk.send_raw({0xFF, 0xFF, 0xFF, 0xF0, 1,  2,  3,  4,  5,  6,  7,  8,  9,  10,
                   11,   12,   13,   14,   15, 16, 17, 18, 19, 20, 21, 22, 23, 24});
    EXPECT_FALSE(junk.pump(200));
  }
  {  // not a VRPN 07 cookie
    Client old;
    old.on_wait = fx.driver();
    ASSERT_TRUE(old.connect_tcp(fx.server->port()));
    old.send_cookie("vrpn: ver. 06.00");
    EXPECT_FALSE(old.pump(200));
  }
  {  // a bad name description (length word beyond the payload)
    Client bad;
    ASSERT_TRUE(fx.connect(bad));
    bad.send_raw(Client::message(-1, 0, {0, 0, 0, 90, 'a', 0}));
    EXPECT_FALSE(bad.pump(200));
  }
  EXPECT_EQ(fx.server->counters().protocol_errors, 3u);
  fx.server->send_frame(two_body_frame(1), 0, mono_now());
  good.pump(50);
  EXPECT_EQ(good.reports.size(), 3u);
  EXPECT_EQ(fx.server->counters().clients_active, 1);
}

TEST(VrpnServer, ListenErrorsAreOneLineWithTheAddress) {
  ServerOptions o;
  EXPECT_FALSE(parse_listen_address("localhost:3883", "--vrpn", o));
  EXPECT_FALSE(parse_listen_address("127.0.0.1:70000", "--vrpn", o));
  ASSERT_TRUE(parse_listen_address("3999", "--vrpn", o));
  EXPECT_EQ(o.address, "127.0.0.1");
  EXPECT_EQ(o.port, 3999);
  Fixture fx;
  ServerOptions same;
  same.port = fx.server->port();
  auto second = Server::create(same, {"arm"});
  ASSERT_FALSE(second);
  EXPECT_NE(
      second.error().message.find("127.0.0.1:" + std::to_string(same.port) + ": cannot listen"),
      std::string::npos)
      << second.error().message;
  EXPECT_EQ(second.error().message.find('\n'), std::string::npos);
}

}  // namespace
}  // namespace mocap::publish::vrpn
