// The "vrpn" output of the registry (pipeline/publish/vrpn/vrpn_sink.cpp): the real-time
// publish() hands frames to the sink's own server thread. Checked with the independent
// test client (vrpn_test_client.h): every frame's reports arrive with the capture time on
// the system clock; a client that never reads costs the publishing thread nothing but
// counted drops (publish() keeps returning true, frames keep flowing to a reading
// client); garbage from a third client ends only that client; the registry's one-line
// errors name the key (bad address, bad option, port in use). Threads: labelled
// concurrency (TSan).
#include <gtest/gtest.h>
#include <time.h>

#include <thread>

#include "pipeline/publish/output_registry.h"
#include "tests/publish/vrpn/vrpn_test_client.h"

namespace mocap::publish {
namespace {

using test::vrpn_client::Client;

struct SinkFixture {
  explicit SinkFixture(std::vector<std::pair<std::string, std::string>> options = {}) {
    for (int b = 0; b < kMaxResultBodies; ++b)  // 32 bodies with velocities: 5.9 KB a frame
      targets.bodies.push_back(MarkerTarget{"b" + std::to_string(b), {}});
    OutputContext ctx;
    ctx.targets = &targets;
    ctx.frame_rate_hz = 100.0;
    OutputRequest r{"vrpn", {"127.0.0.1:0"}, "--vrpn", std::move(options)};
    auto out = create_outputs({r}, ctx);
    EXPECT_TRUE(out) << (out ? "" : out.error().message);
    if (!out) return;
    sinks = std::move(*out);
    sink = sinks.sinks.at(0).get();
    // "vrpn: 32 trackers on 127.0.0.1:PORT (b0@127.0.0.1:PORT, ...)"
    const std::string& n = sinks.notices.at(0);
    const auto colon = n.find("127.0.0.1:");
    port = static_cast<std::uint16_t>(std::stoi(n.substr(colon + 10)));
  }
  FrameResult frame(std::int64_t i) const {
    FrameResult f;
    f.joints.capture_ns = 1'000'000'000 + i * 10'000'000;
    f.body_count = kMaxResultBodies;
    for (std::size_t b = 0; b < f.bodies.size(); ++b) {
      f.bodies[b].found = 1;
      f.bodies[b].velocity_valid = 1;
      f.bodies[b].t_world_body_mm = {static_cast<double>(i), static_cast<double>(b), 0.0};
    }
    return f;
  }
  TargetSet targets;
  Outputs sinks;
  OutputSink* sink = nullptr;
  std::uint16_t port = 0;
};

std::int64_t clock_now(clockid_t id) {
  timespec ts{};
  clock_gettime(id, &ts);
  return std::int64_t{ts.tv_sec} * 1'000'000'000 + ts.tv_nsec;
}

TEST(VrpnSink, FramesReachAReadingClientWhileAnIdleOneOnlyCostsDrops) {
  SinkFixture fx({{"client_buffer_kib", "16"}, {"stall_ms", "60000"}});
  ASSERT_NE(fx.sink, nullptr);
  Client reader, idle, junk;
  for (Client* c : {&reader, &idle, &junk}) {
    ASSERT_TRUE(c->connect_tcp(fx.port));
    c->send_cookie();
  }
  // The server thread answers within its idle period (~100 ms).
  reader.pump(400);
  ASSERT_TRUE(reader.cookie_ok);
  ASSERT_EQ(reader.senders.size(), 32u);
  junk.pump(50);
  junk.send_raw(std::vector<std::uint8_t>(64, 0xEE));
  // The publish thread: frames at ~1 kHz; publish() is a queue copy, always true.
  std::atomic<bool> done{false};
  std::atomic<int> published{0};
  std::thread tracker([&] {
    for (std::int64_t i = 0; i < 2000; ++i) {
      const FrameResult f = fx.frame(i);
      EXPECT_TRUE(fx.sink->publish(f));
      published.fetch_add(1, std::memory_order_relaxed);
      std::this_thread::sleep_for(std::chrono::microseconds(1000));
    }
    done.store(true, std::memory_order_release);
  });
  while (!done.load(std::memory_order_acquire)) reader.pump(20);
  tracker.join();
  reader.pump(300);
  const OutputCounters c = fx.sink->counters();
  EXPECT_EQ(published.load(), 2000);
  EXPECT_GT(c.dropped, 0u);  // the idle client's full buffer, counted
  EXPECT_EQ(reader.protocol_errors, 0);
  // The reader got (nearly) every frame: the sink's queue may drop the oldest under load.
  std::size_t frames_seen = 0;
  for (const auto& r : reader.reports)
    frames_seen += r.body == "b0" && r.type == "vrpn_Tracker Pos_Quat";
  EXPECT_EQ(reader.reports.size(), frames_seen * 2 * kMaxResultBodies);  // whole frames
  EXPECT_GE(frames_seen + c.dropped, 2000u);
  EXPECT_GT(frames_seen, 1000u);
  EXPECT_FALSE(junk.pump(100));  // garbage: that client was closed
  // Message time = capture time on the system clock (offset measured at setup).
  ASSERT_FALSE(reader.reports.empty());
  const auto& r = reader.reports.back();
  const std::int64_t stamp = std::int64_t{r.sec} * 1'000'000'000 + std::int64_t{r.usec} * 1000;
  const std::int64_t offset = clock_now(CLOCK_REALTIME) - clock_now(CLOCK_MONOTONIC);
  const std::int64_t expected =
      std::int64_t{1'000'000'000} + 1999 * std::int64_t{10'000'000} + offset;
  EXPECT_NEAR(static_cast<double>(stamp), static_cast<double>(expected), 5e6);
}

TEST(VrpnSink, RegistryErrorsAreOneLineNamingTheKey) {
  auto check = [](OutputRequest r) {
    auto c = check_outputs({r});
    EXPECT_FALSE(c);
    return c ? std::string() : c.error().message;
  };
  EXPECT_EQ(check({"vrpn", {"nohost:3883"}, "run.yaml: outputs.vrpn", {}}),
            "run.yaml: outputs.vrpn: 'nohost:3883': 'nohost' is not an IPv4 address");
  EXPECT_NE(check({"vrpn", {"3883"}, "--vrpn", {{"max_clients", "0"}}}).find("--vrpn: max_clients"),
            std::string::npos);
  EXPECT_NE(check({"vrpn", {"3883"}, "--vrpn", {{"max_client", "3"}}}).find("unknown option"),
            std::string::npos);
  SinkFixture first;
  ASSERT_NE(first.sink, nullptr);
  TargetSet t;
  t.bodies.push_back(MarkerTarget{"arm", {}});
  OutputContext ctx;
  ctx.targets = &t;
  auto second = create_outputs(
      {OutputRequest{"vrpn", {"127.0.0.1:" + std::to_string(first.port)}, "--vrpn", {}}}, ctx);
  ASSERT_FALSE(second);
  EXPECT_EQ(second.error().message, "--vrpn: 127.0.0.1:" + std::to_string(first.port) +
                                        ": cannot listen: Address already in use");
}

}  // namespace
}  // namespace mocap::publish
