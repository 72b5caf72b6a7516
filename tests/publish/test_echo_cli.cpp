// `mocap echo` as a user runs it: it prints one line per received datagram with the
// sequence gap, stops after --count, and fails with one line (exit 2) when its port is
// taken or RouDi is absent. The datagrams come from our UdpPublisher on 127.0.0.1.
#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <sstream>
#include <thread>
#include <vector>

#include "client/roudi_probe.h"
#include "client/udp_receiver.h"
#include "pipeline/publish/udp_publisher.h"
#include "tests/support/test_support.h"

namespace mocap::publish {
namespace {

client::JointsMessage message(std::uint64_t seq) {
  client::JointsMessage m;
  m.sequence = seq;
  m.capture_ns = 1;
  m.flags = client::kFlagAllBodiesFound;
  m.joint_count = 2;
  m.joints[0].type = 0;
  m.joints[0].valid = 1;
  m.joints[0].a[0] = 0.5f;  // 28.65 deg
  m.joints[1].index = 1;
  m.joints[1].type = 1;
  m.joints[1].valid = 0;
  return m;
}

std::vector<std::string> lines_starting_with(const std::string& text, const std::string& prefix) {
  std::vector<std::string> out;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);)
    if (line.rfind(prefix, 0) == 0) out.push_back(line);
  return out;
}

TEST(EchoCli, PrintsMessagesWithGapsAndStopsAfterCount) {
  // A free port: bind an ephemeral one, note it, release it for echo.
  int port = 0;
  {
    auto probe = client::UdpReceiver::create("127.0.0.1:0");
    ASSERT_TRUE(probe.ok());
    port = probe->port();
  }
  const std::string dest = "127.0.0.1:" + std::to_string(port);
  std::atomic<bool> done{false};
  test::RunResult result;
  std::thread echo([&] {
    result = test::run_mocap("echo --udp " + dest + " --count 3 --duration 20");
    done.store(true, std::memory_order_release);
  });
  auto pub = UdpPublisher::create({dest});
  ASSERT_TRUE(pub.ok()) << pub.error().message;
  // Every third sequence number: each line after the first shows a gap of 2.
  for (std::uint64_t s = 3; !done.load(std::memory_order_acquire) && s < 3 * 4000; s += 3) {
    pub->publish(message(s));
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  echo.join();
  ASSERT_EQ(result.exit_code, 0) << result.output;
  const auto lines = lines_starting_with(result.output, "seq ");
  ASSERT_EQ(lines.size(), 3u) << result.output;
  for (std::size_t i = 1; i < lines.size(); ++i)
    EXPECT_NE(lines[i].find(" gap 2 "), std::string::npos) << lines[i];
  EXPECT_NE(lines[0].find("| j0 ball 28.65 0.00 0.00 | j1 hinge -- deg"), std::string::npos)
      << lines[0];
  EXPECT_NE(result.output.find("mocap echo: "), std::string::npos);
}

// Runs `mocap echo ARGS` on a free port while our UdpPublisher sends every third sequence
// number; returns echo's output once it stopped.
test::RunResult echo_while_publishing(const std::string& args) {
  int port = 0;
  {
    auto probe = client::UdpReceiver::create("127.0.0.1:0");
    if (!probe.ok()) return {};
    port = probe->port();
  }
  const std::string dest = "127.0.0.1:" + std::to_string(port);
  std::atomic<bool> done{false};
  test::RunResult result;
  std::thread echo([&] {
    result = test::run_mocap("echo --udp " + dest + " " + args);
    done.store(true, std::memory_order_release);
  });
  auto pub = UdpPublisher::create({dest});
  for (std::uint64_t s = 3; pub.ok() && !done.load(std::memory_order_acquire) && s < 3 * 4000;
       s += 3) {
    pub->publish(message(s));
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  echo.join();
  return result;
}

TEST(EchoCli, CsvFormatHasHeaderOneRowPerJointAndEmptyQualityOverUdp) {
  const auto r = echo_while_publishing("--count 2 --duration 20 --format csv");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const auto header = lines_starting_with(r.output, "seq,");
  ASSERT_EQ(header.size(), 1u) << r.output;
  EXPECT_EQ(header[0],
            "seq,capture_ns,age_ms,gap,flags,joint,type,valid,a0_deg,a1_deg,a2_deg,qw,qx,qy,qz,"
            "solved_by,sd0_deg,sd1_deg,sd2_deg,da0_deg_s,da1_deg_s,da2_deg_s,sd_da0_deg_s,"
            "sd_da1_deg_s,sd_da2_deg_s");
  std::vector<std::string> rows;
  std::istringstream in(r.output);
  for (std::string line; std::getline(in, line);)
    if (!line.empty() && line[0] >= '0' && line[0] <= '9') rows.push_back(line);
  ASSERT_EQ(rows.size(), 4u) << r.output;  // 2 messages x 2 joints
  for (const std::string& row : rows) EXPECT_EQ(std::count(row.begin(), row.end(), ','), 24) << row;
  // Joint 0: ball, valid, a0 = 0.5 rad; UDP v1 carries no quality and no rates: empty last
  // columns.
  EXPECT_NE(rows[0].find(",0,ball,1,28.647890,0.000000,0.000000,1.000000000,"), std::string::npos)
      << rows[0];
  EXPECT_TRUE(rows[0].ends_with(",1.000000000,0.000000000,0.000000000,0.000000000,,,,,,,,,,"))
      << rows[0];
  EXPECT_NE(rows[1].find(",1,hinge,0,"), std::string::npos) << rows[1];
  // The second message: its gap is the sequence numbers missed since the first (2 when
  // it is the next one sent: every third sequence is; more when a loaded machine let
  // datagrams queue and the receiver took the newest), flags 1.
  const long seq0 = std::stol(rows[0]), seq1 = std::stol(rows[2]);
  ASSERT_GT(seq1, seq0) << rows[2];
  EXPECT_NE(rows[2].find("," + std::to_string(seq1 - seq0 - 1) + ",1,0,ball,"), std::string::npos)
      << rows[2];
}

TEST(EchoCli, JsonFormatIsOneObjectPerMessage) {
  const auto r = echo_while_publishing("--count 2 --duration 20 --format json");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const auto objects = lines_starting_with(r.output, "{");
  ASSERT_EQ(objects.size(), 2u) << r.output;
  for (const std::string& o : objects) {
    EXPECT_TRUE(o.ends_with("}")) << o;
    EXPECT_NE(o.find("\"capture_ns\":1,"), std::string::npos) << o;
    EXPECT_NE(o.find("\"all_bodies_found\":true,\"joints\":[{\"index\":0,\"type\":\"ball\","
                     "\"valid\":true,\"a_rad\":[0.5,0,0],\"q\":[1,0,0,0],\"solved_by\":null,"
                     "\"sd_rad\":null,\"rate_rad_s\":null,\"rate_sd_rad_s\":null},{\"index\":1,"
                     "\"type\":\"hinge\",\"valid\":false,"),
              std::string::npos)
        << o;
  }
  EXPECT_NE(objects[1].find("\"gap\":2,"), std::string::npos) << objects[1];
}

TEST(EchoCli, UnknownFormatIsOneLine) {
  const auto r = test::run_mocap("echo --format xml --count 1");
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.output.find("--format"), std::string::npos) << r.output;
}

TEST(EchoCli, PortInUseIsOneLine) {
  auto taken = client::UdpReceiver::create("127.0.0.1:0");
  ASSERT_TRUE(taken.ok());
  const auto r =
      test::run_mocap("echo --udp 127.0.0.1:" + std::to_string(taken->port()) + " --count 1");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.output.find("bind: Address already in use"), std::string::npos) << r.output;
  EXPECT_EQ(lines_starting_with(r.output, "mocap").size(), 1u) << r.output;
}

TEST(EchoCli, IceoryxWithoutRouDiIsOneLine) {
  if (client::roudi_running()) GTEST_SKIP() << "a RouDi runs on this machine";
  const auto r = test::run_mocap("echo --iceoryx --count 1");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.output.find("RouDi (iox-roudi) not running"), std::string::npos) << r.output;
}

}  // namespace
}  // namespace mocap::publish
