// Design: a rig of more than 8 cameras over camera nodes (issue 29, kMaxCameras = 32) on
// loopback: a 12-camera humanoid recording (fixture node_recording_wide, 10 frames) split
// over two `mocap node` processes of 6 replay cameras each (`trigger: central`), and one
// central with 12 `backend: node` cameras. `mocap run` (pacing lockstep) publishes every
// frame with the joint angles of the same recording replayed by one process through 12
// local replay cameras (UDP datagrams, equal within 1e-5 rad); `mocap record --blobs` of
// the two nodes tracks to the poses of tracking the 12-camera images offline. Each test
// uses its own DDS domain id (no cross-talk with concurrent test processes).
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <fstream>
#include <map>
#include <string>
#include <vector>

#include "client/datagram.h"
#include "tests/support/test_support.h"
#include "tests/support/udp_port.h"

namespace mocap {
namespace {

#ifndef MOCAP_TEST_WIDE_RECORDING
#define MOCAP_TEST_WIDE_RECORDING "node_recording_wide"
#endif
constexpr int kWideFrames = MOCAP_TEST_WIDE_FRAMES;
constexpr int kWideCameras = 12;
constexpr int kCamerasPerNode = 6;

std::string wide_recording() { return MOCAP_TEST_WIDE_RECORDING; }

// capture_ns -> every joint's a[3] (NaN where not valid), from the datagrams received.
std::map<std::int64_t, std::vector<float>> wide_angles(const test::KeepAllUdpSocket& sock) {
  std::map<std::int64_t, std::vector<float>> angles;
  std::uint8_t buf[client::kMaxDatagramBytes + 16];
  for (;;) {
    const ssize_t n = sock.receive(buf, sizeof buf);
    if (n <= 0) break;
    client::JointsMessage m;
    if (client::decode_datagram(buf, static_cast<std::size_t>(n), m) != client::DecodeStatus::kOk)
      continue;
    std::vector<float>& a = angles[m.capture_ns];
    for (int j = 0; j < m.joint_count; ++j)
      for (float v : m.joints[j].a) a.push_back(m.joints[j].valid ? v : NAN);
  }
  return angles;
}

class WideNodeCluster : public ::testing::Test {
 protected:
  void SetUp() override {
    const std::string name = ::testing::UnitTest::GetInstance()->current_test_info()->name();
    dir_ = ::testing::TempDir() + "node_wide_" + std::to_string(::getpid()) + "_" + name;
    ASSERT_EQ(test::run_command("rm -rf '" + dir_ + "' && mkdir -p '" + dir_ + "'").exit_code, 0);
    // 1..231 as test_node_cluster's, on other residues of the pid (0 is left to users).
    domain_ = 1 + (static_cast<int>(::getpid()) % 38) * 6 + 3 +
              (name.find("Blob") != std::string::npos ? 1 : 0);
  }
  void write(const std::string& name, const std::string& text) const {
    std::ofstream(dir_ + "/" + name) << text;
  }
  std::string tracker_keys(int port) const {
    return "targets: " + wide_recording() + "/targets.yaml\nmodel: " + wide_recording() +
           "/gt/model_true.yaml\npipeline: {pacing: lockstep, trigger_rate_hz: 50, realtime: "
           "false, lock_memory: false}\noutputs: {udp: [127.0.0.1:" +
           std::to_string(port) + "], iceoryx: false}\n";
  }
  // Node n replays cameras 6n..6n+5; the central lists all 12 as node cameras.
  void write_cluster(int port) const {
    for (int n = 0; n < 2; ++n) {
      std::string y = "node: {name: w" + std::to_string(n) +
                      ", domain_id: " + std::to_string(domain_) +
                      "}\npipeline: {realtime: false}\ncameras:\n";
      for (int c = kCamerasPerNode * n; c < kCamerasPerNode * (n + 1); ++c)
        y += "  - {backend: replay, device: " + wide_recording() + ", camera: cam" +
             std::to_string(c) + ", trigger: central}\n";
      write("node" + std::to_string(n) + ".yaml", y);
    }
    std::string y = "node: {domain_id: " + std::to_string(domain_) +
                    ", wait_s: 20, timeout_ms: 5000}\nrig: " + wide_recording() +
                    "/rig.yaml\ncameras:\n";
    for (int c = 0; c < kWideCameras; ++c)
      y += "  - {backend: node, device: w" + std::to_string(c / kCamerasPerNode) + "/cam" +
           std::to_string(c) + "}\n";
    write("central.yaml", y + tracker_keys(port));
  }
  // Both nodes in the background, the central (`mocap ARGS`) in the foreground.
  test::RunResult run_cluster(const std::string& central_args) const {
    const std::string m = test::mocap_binary();
    const std::string d = "'" + dir_ + "'";
    const std::string cmd =
        "cd " + d + " && { " + m + " node --config node0.yaml --duration 120 > node0.log 2>&1 & " +
        m + " node --config node1.yaml --duration 120 > node1.log 2>&1 & }; timeout 120 " + m +
        " " + central_args + " > central.log 2>&1; rc=$?; wait; cat central.log node0.log " +
        "node1.log; exit $rc";
    return test::run_command(cmd);
  }
  std::string dir_;
  int domain_ = 1;
};

TEST_F(WideNodeCluster, TwelveNodeCamerasPublishEveryFrameWithTheSingleProcessAngles) {
  test::KeepAllUdpSocket single_sock(300'000), nodes_sock(300'000);
  ASSERT_TRUE(single_sock.ok() && nodes_sock.ok());
  // The reference: one process, 12 local replay cameras (a local rig of more than 8).
  std::string single = "cameras:\n";
  for (int c = 0; c < kWideCameras; ++c)
    single += "  - {backend: replay, device: " + wide_recording() + ", trigger: software}\n";
  write("single.yaml", single + tracker_keys(single_sock.port()));
  const test::RunResult one =
      test::run_mocap("run --config '" + dir_ + "/single.yaml' --stats-interval 0", 120);
  ASSERT_EQ(one.exit_code, 0) << one.output;
  const auto ref = wide_angles(single_sock);
  ASSERT_EQ(static_cast<int>(ref.size()), kWideFrames) << one.output;

  write_cluster(nodes_sock.port());
  const test::RunResult r = run_cluster("run --config central.yaml --stats-interval 0");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("the recording ended"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("node:w1/cam11: frames " + std::to_string(kWideFrames)),
            std::string::npos)
      << r.output;
  const auto got = wide_angles(nodes_sock);
  ASSERT_EQ(got.size(), ref.size()) << r.output;
  double worst = 0.0;
  int compared = 0;
  for (const auto& [capture_ns, a] : ref) {
    const auto it = got.find(capture_ns);
    ASSERT_NE(it, got.end()) << "frame at " << capture_ns << " not published\n" << r.output;
    ASSERT_EQ(it->second.size(), a.size());
    for (std::size_t i = 0; i < a.size(); ++i) {
      ASSERT_EQ(std::isnan(a[i]), std::isnan(it->second[i])) << "joint validity differs";
      if (std::isnan(a[i])) continue;
      worst = std::max(worst, static_cast<double>(std::fabs(a[i] - it->second[i])));
      ++compared;
    }
  }
  EXPECT_GT(compared, 14 * 3 * kWideFrames / 2);  // most of the 14 joints' angles, valid
  EXPECT_LE(worst, 1e-5);
}

TEST_F(WideNodeCluster, BlobRecordingOfTwelveNodeCamerasTracksAsTheImages) {
  write_cluster(test::free_udp_port());
  const test::RunResult r = run_cluster(
      "record --blobs --config central.yaml --out blobrec "
      "--progress-interval 0");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find(std::to_string(kWideFrames) + " frames triggered, " +
                          std::to_string(kWideFrames) + " written, 0 not written"),
            std::string::npos)
      << r.output;
  EXPECT_TRUE(std::ifstream(dir_ + "/blobrec/blobs/cam11.blobs").good());
  const std::string targets = " --targets " + wide_recording() + "/targets.yaml --quiet";
  const test::RunResult a = test::run_mocap(
      "track " + wide_recording() + targets + " --out '" + dir_ + "/from_images'", 120);
  ASSERT_EQ(a.exit_code, 0) << a.output;
  const test::RunResult b = test::run_mocap(
      "track '" + dir_ + "/blobrec'" + targets + " --out '" + dir_ + "/from_blobs'", 120);
  ASSERT_EQ(b.exit_code, 0) << b.output;
  const std::string poses_images = test::read_file(dir_ + "/from_images/poses.csv");
  EXPECT_GT(poses_images.size(), 1000u);
  EXPECT_EQ(test::read_file(dir_ + "/from_blobs/poses.csv"), poses_images);
  // The 12-camera points.csv ends with the `cameras` column: some points from more than 8.
  const std::string points = test::read_file(dir_ + "/from_blobs/points.csv");
  ASSERT_EQ(points.rfind("frame,x,y,z,reproj_px,cameras\n", 0), 0u) << points.substr(0, 80);
  int most = 0;
  for (std::size_t end = points.find('\n'); end + 1 < points.size();) {
    const std::size_t next = points.find('\n', end + 1);
    const std::string row = points.substr(end + 1, next - end - 1);
    most = std::max(most, std::stoi(row.substr(row.rfind(',') + 1)));
    end = next;
  }
  EXPECT_GT(most, 8);
  EXPECT_LE(most, kWideCameras);
}

}  // namespace
}  // namespace mocap
