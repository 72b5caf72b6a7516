// `mocap run --vrpn` end to end: the built tracker runs the simulated rig at 100 Hz for
// 3 seconds with UDP datagrams to this test (the reference: one per frame, with its
// capture time) and the VRPN server on a free port; the independent test client
// (vrpn_test_client.h) connects over TCP, a second one by the UDP connection request
// (the server connects back) and asks for UDP reports; both read until the tracker exits. Checked:
// 0 protocol errors; every body of targets.yaml is described; every body's Pos_Quat arrives for >=
// 95 % of the frames the datagrams carry while the client was connected; each report's time is a
// frame's capture time on the system clock (matched to a datagram's CLOCK_MONOTONIC capture time
// through this machine's realtime - monotonic offset, within 1 ms); quaternions are unit, positions
// in metres; Velocity reports (the tracker's body velocities) follow for >= 90 % of them.
#include <gtest/gtest.h>
#include <time.h>

#include <cmath>
#include <cstdio>
#include <map>
#include <set>
#include <thread>

#include "client/datagram.h"
#include "tests/publish/vrpn/vrpn_test_client.h"
#include "tests/support/test_support.h"
#include "tests/support/udp_port.h"

namespace mocap {
namespace {

std::int64_t now_on(clockid_t id) {
  timespec ts{};
  clock_gettime(id, &ts);
  return std::int64_t{ts.tv_sec} * 1'000'000'000 + ts.tv_nsec;
}

TEST(VrpnRun, EveryBodyAtTheFrameRateWithCaptureTimes) {
  const test::KeepAllUdpSocket udp_rx(1000);
  ASSERT_TRUE(udp_rx.ok());
  const int port = test::free_udp_port();  // VRPN binds TCP and UDP on it
  ASSERT_GT(port, 0);
  test::RunResult run;
  std::atomic<bool> exited{false};
  std::thread tracker([&] {
    run = test::run_command("timeout -s KILL 90 " + test::mocap_binary() +
                            " run --vrpn 127.0.0.1:" + std::to_string(port) +
                            " --duration 3 --rate 100 --loop-frames 4 --no-realtime --no-iceoryx"
                            " --stats-interval 0 --udp 127.0.0.1:" +
                            std::to_string(udp_rx.port()) + " 2>&1");
    exited.store(true);
  });
  std::vector<std::int64_t> captures;  // datagram capture times (CLOCK_MONOTONIC)
  auto drain_udp = [&] {
    std::uint8_t buf[4096];
    for (ssize_t n; (n = udp_rx.receive(buf, sizeof buf)) > 0;) {
      client::JointsMessage m;
      if (client::decode_datagram(buf, static_cast<std::size_t>(n), m) == client::DecodeStatus::kOk)
        captures.push_back(m.capture_ns);
    }
  };
  test::vrpn_client::Client c;
  bool connected = false;
  while (!connected && !exited.load()) {  // the server listens once the sim loop is rendered
    drain_udp();
    connected = c.connect_tcp(static_cast<std::uint16_t>(port));
    if (!connected) std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  ASSERT_TRUE(connected) << run.output;
  c.send_cookie();
  // A second client the way vrpn_mocap and libmotioncapture connect: the UDP connection
  // request (the server connects back), then reports by UDP (its UDP description).
  test::vrpn_client::Client viaudp;
  viaudp.on_wait = drain_udp;
  ASSERT_TRUE(viaudp.request_connect_back(static_cast<std::uint16_t>(port)));
  viaudp.send_cookie();
  ASSERT_TRUE(viaudp.ask_udp());
  for (bool a = true, b = true; a || b;) {  // until the tracker exits and closes both
    if (a) a = c.pump(2);
    if (b) b = viaudp.pump(2);
    drain_udp();
  }
  tracker.join();
  drain_udp();
  ASSERT_EQ(run.exit_code, 0) << run.output;
  EXPECT_NE(run.output.find("vrpn: "), std::string::npos) << run.output;

  // Reports -> frames: report time - offset = a datagram's capture time (within 1 ms).
  const std::int64_t offset = now_on(CLOCK_REALTIME) - now_on(CLOCK_MONOTONIC);
  const std::set<std::int64_t> frames(captures.begin(), captures.end());
  for (const test::vrpn_client::Client* client : {&c, &viaudp}) {
    const bool udp = client == &viaudp;
    SCOPED_TRACE(udp ? "connect-back, UDP reports" : "direct TCP");
    EXPECT_EQ(client->protocol_errors, 0);
    ASSERT_TRUE(client->cookie_ok);
    ASSERT_GE(client->senders.size(), 2u);
    ASSERT_FALSE(client->reports.empty()) << run.output;
    std::map<std::string, std::set<std::int64_t>> per_body;
    std::map<std::string, int> velocities;  // Velocity reports per body (the body rates)
    std::int64_t first = INT64_MAX;
    int unmatched = 0, wrong_path = 0;
    for (const auto& r : client->reports) {
      if (r.type == "vrpn_Tracker Velocity") {
        ++velocities[r.body];
        EXPECT_LT(std::fabs(r.vel[0]) + std::fabs(r.vel[1]) + std::fabs(r.vel[2]), 20.0);  // m/s
        continue;
      }
      if (r.type != "vrpn_Tracker Pos_Quat") continue;
      wrong_path += !udp && r.via_udp ? 1 : 0;  // the TCP client never asked for UDP
      const std::int64_t t =
          std::int64_t{r.sec} * 1'000'000'000 + std::int64_t{r.usec} * 1000 - offset;
      auto it = frames.lower_bound(t - 1'000'000);
      if (it == frames.end() || std::llabs(*it - t) > 1'000'000) {
        ++unmatched;
        continue;
      }
      per_body[r.body].insert(*it);
      first = std::min(first, *it);
      const double qn = std::sqrt(r.quat[0] * r.quat[0] + r.quat[1] * r.quat[1] +
                                  r.quat[2] * r.quat[2] + r.quat[3] * r.quat[3]);
      EXPECT_NEAR(qn, 1.0, 1e-6);
      EXPECT_LT(std::fabs(r.pos[0]) + std::fabs(r.pos[1]) + std::fabs(r.pos[2]), 10.0);  // m
    }
    EXPECT_EQ(unmatched, 0);
    EXPECT_EQ(wrong_path, 0);
    if (udp) {
      EXPECT_TRUE(client->reports.back().via_udp);
    }
    // Connected until the tracker exits: the window runs to the run's last frame.
    const auto expected =
        static_cast<double>(std::distance(frames.lower_bound(first), frames.end()));
    ASSERT_GT(expected, 100.0) << "connected for too few frames";
    for (const auto& [id, name] : client->senders) {
      std::printf("vrpn run (%s): %s: Pos_Quat in %zu of %.0f frames\n",
                  udp ? "connect-back, UDP" : "TCP", name.c_str(), per_body[name].size(), expected);
      EXPECT_GE(static_cast<double>(per_body[name].size()), 0.95 * expected)
          << name << ": " << per_body[name].size() << " of " << expected << " frames";
      // Velocities from the third frame a body is found on (kinematics/body_rates.h).
      EXPECT_GE(static_cast<double>(velocities[name]), 0.9 * expected)
          << name << ": " << velocities[name] << " Velocity reports";
    }
  }
}

}  // namespace
}  // namespace mocap
