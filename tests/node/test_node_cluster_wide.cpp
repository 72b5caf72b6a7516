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
#include <fstream>
#include <string>

#include "tests/node/node_cluster_util.h"
#include "tests/support/test_support.h"
#include "tests/support/udp_port.h"

namespace mocap {
namespace {

#ifndef MOCAP_TEST_NODE_RECORDING
#define MOCAP_TEST_NODE_RECORDING "node_recording_wide"
#endif
constexpr int kWideFrames = MOCAP_TEST_NODE_FRAMES;
constexpr int kWideCameras = 12;
constexpr int kCamerasPerNode = 6;

std::string wide_recording() { return MOCAP_TEST_NODE_RECORDING; }

class WideNodeCluster : public ::testing::Test {
 protected:
  // Node wN replays cameras 6N..6N+5; the central lists all 12 as node cameras.
  void SetUp() override {
    const std::string name = ::testing::UnitTest::GetInstance()->current_test_info()->name();
    cluster_.dir = test::node_cluster::fresh_test_dir("node_wide");
    cluster_.recording = wide_recording();
    cluster_.node_name = "w";
    cluster_.cameras_per_node = kCamerasPerNode;
    // 1..231 as test_node_cluster's, on other residues of the pid (0 is left to users).
    cluster_.domain_id = 1 + (static_cast<int>(::getpid()) % 38) * 6 + 3 +
                         (name.find("Blob") != std::string::npos ? 1 : 0);
  }
  static std::string tracker_keys(int port) {
    return test::node_cluster::tracker_keys(wide_recording(),
                                            "pacing: lockstep, trigger_rate_hz: 50", port);
  }
  test::node_cluster::Cluster cluster_;
};

TEST_F(WideNodeCluster, TwelveNodeCamerasPublishEveryFrameWithTheSingleProcessAngles) {
  test::KeepAllUdpSocket single_sock(300'000), nodes_sock(300'000);
  ASSERT_TRUE(single_sock.ok() && nodes_sock.ok());
  // The reference: one process, 12 local replay cameras (a local rig of more than 8).
  const test::RunResult one = cluster_.run_single_process(tracker_keys(single_sock.port()));
  ASSERT_EQ(one.exit_code, 0) << one.output;
  const auto ref = test::node_cluster::drain(single_sock).angles;
  ASSERT_EQ(static_cast<int>(ref.size()), kWideFrames) << one.output;

  cluster_.write_configs(tracker_keys(nodes_sock.port()));
  const test::RunResult r = cluster_.run("run --config central.yaml --stats-interval 0");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("the recording ended"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("node:w1/cam11: frames " + std::to_string(kWideFrames)),
            std::string::npos)
      << r.output;
  // Most of the 14 joints' angles valid.
  test::node_cluster::expect_same_angles(ref, test::node_cluster::drain(nodes_sock).angles, 1e-5,
                                         14 * 3 * kWideFrames / 2, r.output);
}

TEST_F(WideNodeCluster, BlobRecordingOfTwelveNodeCamerasTracksAsTheImages) {
  cluster_.write_configs(tracker_keys(test::free_udp_port()));
  const test::RunResult r = cluster_.run(
      "record --blobs --config central.yaml --out blobrec "
      "--progress-interval 0");
  cluster_.expect_blob_recording_tracks_as_images(r, kWideFrames);
  if (::testing::Test::HasFatalFailure()) return;
  EXPECT_TRUE(std::ifstream(cluster_.dir + "/blobrec/blobs/cam11.blobs").good());
  // The 12-camera points.csv ends with the `cameras` column: some points from more than 8.
  const std::string points = test::read_file(cluster_.dir + "/from_blobs/points.csv");
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
