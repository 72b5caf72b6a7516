// End-to-end test of the camera nodes (issue 29) on loopback: two `mocap node` processes
// replay 4 cameras each of an 8-camera recording (fixture node_recording) with `trigger:
// central`, and one central `mocap run` (pacing lockstep, cameras `backend: node`) tracks
// them (node n0 on one detection worker, n1 on the default count, min(4 cameras, CPUs)).
// Checked against the same recording replayed in one process: every frame is
// published and the joint angles (UDP datagrams) are equal within 1e-5 rad; with one node
// killed mid-run the central goes on publishing from the other node's cameras and ends
// normally when the replay ends; the node restarted is used again, in step (its replay
// plays the frame the central's trigger names); with hardware-triggered nodes (the central
// does not trigger) a killed node's cameras become silent and the sets go on without them;
// `mocap record --blobs` of the two nodes tracks to the image recording's poses. Each test
// uses its own DDS domain id (no cross-talk between concurrent test processes).
#include <gtest/gtest.h>
#include <unistd.h>

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

#ifndef MOCAP_TEST_NODE_RECORDING
#define MOCAP_TEST_NODE_RECORDING "node_recording"
#endif
constexpr int kFrames = MOCAP_TEST_NODE_FRAMES;

std::string recording() { return MOCAP_TEST_NODE_RECORDING; }

struct Published {
  std::map<std::int64_t, std::vector<float>> angles;  // capture_ns -> every joint's a[3]
  int datagrams = 0;
};

Published drain(const test::KeepAllUdpSocket& sock) {
  Published p;
  std::uint8_t buf[client::kMaxDatagramBytes + 16];
  for (;;) {
    const ssize_t n = sock.receive(buf, sizeof buf);
    if (n <= 0) break;
    client::JointsMessage m;
    if (client::decode_datagram(buf, static_cast<std::size_t>(n), m) != client::DecodeStatus::kOk)
      continue;
    ++p.datagrams;
    std::vector<float>& a = p.angles[m.capture_ns];
    for (int j = 0; j < m.joint_count; ++j) {
      for (float v : m.joints[j].a) a.push_back(m.joints[j].valid ? v : NAN);
    }
  }
  return p;
}

class NodeCluster : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = ::testing::TempDir() + "node_cluster_" + std::to_string(::getpid()) + "_" +
           ::testing::UnitTest::GetInstance()->current_test_info()->name();
    ASSERT_EQ(test::run_command("rm -rf '" + dir_ + "' && mkdir -p '" + dir_ + "'").exit_code, 0);
    // A domain of its own per test process and test (1..231; 0 is left to users).
    const std::string name = ::testing::UnitTest::GetInstance()->current_test_info()->name();
    const int index = name.find("Killed") != std::string::npos   ? 1
                      : name.find("Silent") != std::string::npos ? 2
                                                                 : 0;
    domain_ = 1 + (static_cast<int>(::getpid()) % 77) * 3 + index;
  }
  void write(const std::string& name, const std::string& text) {
    std::ofstream(dir_ + "/" + name) << text;
  }
  std::string tracker_keys(int port, double rate_hz) const {
    return "targets: " + recording() + "/targets.yaml\nmodel: " + recording() +
           "/gt/model_true.yaml\npipeline: {pacing: lockstep, trigger_rate_hz: " +
           std::to_string(rate_hz) +
           ", realtime: false, lock_memory: false}\noutputs: {udp: [127.0.0.1:" +
           std::to_string(port) + "], iceoryx: false}\n";
  }
  // Two nodes of 4 replay cameras each and the central's 8 node cameras. node_pipeline:
  // the nodes' pipeline keys; node_trigger: their cameras' trigger; central_trigger: the
  // central cameras' (empty: none given). timeout_ms: how long the central waits for a
  // node's frame before it is missing (the sanitizer builds' nodes take ~0.1-0.3 s per frame).
  void write_nodes_and_central(const std::string& node_pipeline, const std::string& node_trigger,
                               const std::string& central_trigger, int timeout_ms,
                               const std::string& central_keys) {
    for (int n = 0; n < 2; ++n) {
      // Central-triggered: node n0 detects on one worker, n1 on the default count.
      const std::string workers = n == 0 && node_trigger == "central" ? ", detect_threads: 1" : "";
      std::string y = "node: {name: n" + std::to_string(n) +
                      ", domain_id: " + std::to_string(domain_) + workers + "}\npipeline: {" +
                      node_pipeline + "}\ncameras:\n";
      for (int c = 4 * n; c < 4 * n + 4; ++c)
        y += "  - {backend: replay, device: " + recording() + ", camera: cam" + std::to_string(c) +
             ", trigger: " + node_trigger + "}\n";
      write("node" + std::to_string(n) + ".yaml", y);
    }
    std::string y = "node: {domain_id: " + std::to_string(domain_) +
                    ", wait_s: 20, timeout_ms: " + std::to_string(timeout_ms) +
                    "}\nrig: " + recording() + "/rig.yaml\ncameras:\n";
    for (int c = 0; c < 8; ++c)
      y += "  - {backend: node, device: n" + std::to_string(c / 4) + "/cam" + std::to_string(c) +
           (central_trigger.empty() ? "" : ", trigger: " + central_trigger) + "}\n";
    write("central.yaml", y + central_keys);
  }
  // The nodes follow the central's triggers (lockstep at rate_hz).
  void write_cluster(int port, double rate_hz, int timeout_ms) {
    write_nodes_and_central("realtime: false", "central", "", timeout_ms,
                            tracker_keys(port, rate_hz));
  }
  // The reference: the recording replayed by one process (8 local replay cameras).
  Published single_process(const test::KeepAllUdpSocket& sock) {
    std::string single = "cameras:\n";
    for (int c = 0; c < 8; ++c)
      single += "  - {backend: replay, device: " + recording() + ", trigger: software}\n";
    write("single.yaml", single + tracker_keys(sock.port(), 100.0));
    const test::RunResult one =
        test::run_mocap("run --config '" + dir_ + "/single.yaml' --stats-interval 0", 120);
    EXPECT_EQ(one.exit_code, 0) << one.output;
    return drain(sock);
  }
  // Hardware-trigger-like: each node triggers its replay cameras itself at rate_hz
  // (`trigger: software` on the node: the frames keep the recording's numbers, as cameras
  // on one trigger line count together) and the central does not trigger (`trigger:
  // external` on its node cameras), pairing by sequence.
  void write_external_cluster(int port, double rate_hz, int timeout_ms) {
    write_nodes_and_central(
        "realtime: false, trigger_rate_hz: " + std::to_string(rate_hz), "software", "external",
        timeout_ms,
        "targets: " + recording() + "/targets.yaml\nmodel: " + recording() +
            "/gt/model_true.yaml\npipeline: {pair_by: sequence, trigger_rate_hz: " +
            std::to_string(rate_hz) +
            ", realtime: false, lock_memory: false}\noutputs: {udp: [127.0.0.1:" +
            std::to_string(port) + "], iceoryx: false}\n");
  }

  // Both nodes in the background, the central in the foreground; `kill_after_s` > 0
  // SIGKILLs node n1 that long after the central started, `restart_after_s` > 0 starts it
  // again that much later (its replay joins at the frame the next central trigger names).
  test::RunResult run_cluster(double kill_after_s, double restart_after_s = 0.0,
                              const std::string& central = "run") {
    const std::string m = test::mocap_binary();
    const std::string d = "'" + dir_ + "'";
    std::string cmd = "cd " + d + " && " + m +
                      " node --config node0.yaml --duration 120 > node0.log 2>&1 & " + "cd " + d +
                      " && " + m +
                      " node --config node1.yaml --duration 120 > node1.log 2>&1 & B=$!; ";
    if (kill_after_s > 0) {
      cmd += "(sleep " + std::to_string(kill_after_s) + "; kill -9 $B";
      if (restart_after_s > 0)
        cmd +=
            "; sleep " + std::to_string(restart_after_s) + "; cd " + d + " && { " + m +
            " node --config node1.yaml --duration 20 > node1b.log 2>&1 & echo $! > node1b.pid; }";
      cmd += ") & ";
    }
    const std::string how = central == "run"
                                ? " run --config " + d + "/central.yaml --stats-interval 0"
                                : " record --blobs --config " + d + "/central.yaml --out " + d +
                                      "/blobrec --progress-interval 0";
    cmd += "timeout 120 " + m + how + " > " + d + "/central.log 2>&1; rc=$?; wait; [ -f " + d +
           "/node1b.pid ] && kill $(cat " + d + "/node1b.pid); sleep 0.5; cat " + d +
           "/central.log " + d + "/node0.log; [ -f " + d + "/node1b.log ] && cat " + d +
           "/node1b.log; exit $rc";
    return test::run_command(cmd);
  }
  std::string dir_;
  int domain_ = 1;
};

TEST_F(NodeCluster, TwoNodesPublishEveryFrameWithTheSingleProcessAngles) {
  test::KeepAllUdpSocket single_sock(300'000), nodes_sock(300'000);
  ASSERT_TRUE(single_sock.ok() && nodes_sock.ok());
  const Published ref = single_process(single_sock);
  ASSERT_EQ(static_cast<int>(ref.angles.size()), kFrames);

  write_cluster(nodes_sock.port(), 100.0, 5000);  // no node dies: wait for every frame
  const test::RunResult r = run_cluster(0.0);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("the recording ended"), std::string::npos) << r.output;
  const Published got = drain(nodes_sock);
  EXPECT_EQ(got.datagrams, kFrames) << r.output;
  ASSERT_EQ(got.angles.size(), ref.angles.size()) << r.output;
  double worst = 0.0;
  int compared = 0;
  for (const auto& [capture_ns, a] : ref.angles) {
    const auto it = got.angles.find(capture_ns);
    ASSERT_NE(it, got.angles.end()) << "frame at " << capture_ns << " not published";
    ASSERT_EQ(it->second.size(), a.size());
    for (std::size_t i = 0; i < a.size(); ++i) {
      ASSERT_EQ(std::isnan(a[i]), std::isnan(it->second[i])) << "joint validity differs";
      if (std::isnan(a[i])) continue;
      worst = std::max(worst, static_cast<double>(std::fabs(a[i] - it->second[i])));
      ++compared;
    }
  }
  EXPECT_GT(compared, kFrames);
  EXPECT_LE(worst, 1e-5);
}

TEST_F(NodeCluster, AKilledNodesCamerasGoMissingComeBackAndTheRunEndsNormally) {
  test::KeepAllUdpSocket sock(300'000);
  ASSERT_TRUE(sock.ok());
  write_cluster(sock.port(), 10.0, 500);  // 10 Hz: the kill and the restart land mid-run
  const test::RunResult r = run_cluster(0.3 * kFrames / 10.0 + 0.5, 0.3);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("the recording ended"), std::string::npos) << r.output;
  const Published got = drain(sock);
  // Frames after the kill are published from node n0's cameras alone.
  EXPECT_GE(got.datagrams, kFrames / 2) << r.output;
  // The kill made node n1's cameras miss frames (the set went on without them)...
  const std::size_t at = r.output.find("node:n1/cam4: frames");
  ASSERT_NE(at, std::string::npos) << r.output;
  const std::size_t missing = r.output.find("missing ", at);
  ASSERT_NE(missing, std::string::npos) << r.output;
  EXPECT_GT(std::stol(r.output.substr(missing + 8)), 0) << r.output;
  // ... and the node came back (a new process: its report "camera cam4: ...") and the
  // central took its frames (all but a few that may have come late).
  const std::size_t again = r.output.find("camera cam4: frames ");
  ASSERT_NE(again, std::string::npos) << "node n1 was not restarted\n" << r.output;
  const long sent_again = std::stol(r.output.substr(again + 20));
  EXPECT_GT(sent_again, 0) << r.output;
  const long central_frames = std::stol(r.output.substr(at + 21));
  EXPECT_GT(central_frames, sent_again - 3) << r.output;  // a few may come late
  // The restarted replay followed the central's trigger numbers: it skipped the frames
  // played before it came back instead of starting at its first frame, and played the
  // rest up to the end (the frame trigger k names is the recording's k-th).
  const std::size_t skipped_at = r.output.find(", skipped ", again);
  ASSERT_NE(skipped_at, std::string::npos) << r.output;
  const long skipped = std::stol(r.output.substr(skipped_at + 10));
  EXPECT_GT(skipped, 0) << r.output;
  EXPECT_GE(sent_again + skipped, kFrames - 1) << r.output;
  EXPECT_LE(sent_again + skipped, kFrames) << r.output;
  // In step: the last frame (all 8 cameras again) has the one-process angles.
  test::KeepAllUdpSocket single_sock(300'000);
  ASSERT_TRUE(single_sock.ok());
  const Published ref = single_process(single_sock);
  ASSERT_FALSE(ref.angles.empty());
  ASSERT_FALSE(got.angles.empty());
  const auto& [last_ns, last] = *ref.angles.rbegin();
  ASSERT_EQ(got.angles.rbegin()->first, last_ns) << r.output;
  const std::vector<float>& mine = got.angles.rbegin()->second;
  ASSERT_EQ(mine.size(), last.size());
  for (std::size_t i = 0; i < last.size(); ++i) {
    if (std::isnan(last[i])) continue;
    EXPECT_NEAR(mine[i], last[i], 1e-5) << "angle " << i << "\n" << r.output;
  }
}

// Hardware-triggered nodes (the central does not trigger): node n1 killed mid-run. Its
// cameras become silent after node.timeout_ms + a trigger period, the sets go on from
// node n0's cameras (counted in frames_without_silent_cameras), and the run ends when
// n0's replay ends. Before issue 29's fix the sets waited for n1 forever (no frame
// published after the kill, the run never ended: timeout).
TEST_F(NodeCluster, ASilentHardwareTriggeredNodeDoesNotStallTheFrameSets) {
  test::KeepAllUdpSocket sock(300'000);
  ASSERT_TRUE(sock.ok());
  write_external_cluster(sock.port(), 5.0, 300);  // 30 frames at 5 Hz: 6 s; bound 0.5 s
  const test::RunResult r = run_cluster(3.5);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("the recording ended"), std::string::npos) << r.output;
  auto counter = [&](const std::string& name) -> long {
    const std::size_t at = r.output.find(" " + name + "=");
    return at == std::string::npos ? -1 : std::stol(r.output.substr(at + name.size() + 2));
  };
  const long partial = counter("frames_without_silent_cameras");
  EXPECT_GE(partial, 3) << r.output;  // the frames after the kill (n0 went on ~2 s)
  EXPECT_EQ(counter("pair_silent_cam4"), 1) << r.output;
  EXPECT_EQ(counter("pair_silent_cam0"), 0) << r.output;
  EXPECT_EQ(counter("pair_absent_cam7"), partial) << r.output;
  const Published got = drain(sock);
  EXPECT_GE(got.datagrams, partial + 3) << r.output;  // full sets before the kill too
}

// `mocap record --blobs` takes node cameras: the blob recording of the two nodes tracks
// to the same poses as the image recording they replayed.
TEST_F(NodeCluster, BlobRecordingOfTwoNodesTracksAsTheImages) {
  write_cluster(test::free_udp_port(), 100.0, 5000);
  const test::RunResult r = run_cluster(0.0, 0.0, "record");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find(std::to_string(kFrames) + " frames triggered, " +
                          std::to_string(kFrames) + " written, 0 not written"),
            std::string::npos)
      << r.output;
  const std::string targets = " --targets " + recording() + "/targets.yaml --quiet";
  const test::RunResult a =
      test::run_mocap("track " + recording() + targets + " --out '" + dir_ + "/from_images'", 120);
  ASSERT_EQ(a.exit_code, 0) << a.output;
  const test::RunResult b = test::run_mocap(
      "track '" + dir_ + "/blobrec'" + targets + " --out '" + dir_ + "/from_blobs'", 120);
  ASSERT_EQ(b.exit_code, 0) << b.output;
  const std::string poses_images = test::read_file(dir_ + "/from_images/poses.csv");
  EXPECT_GT(poses_images.size(), 1000u);
  EXPECT_EQ(test::read_file(dir_ + "/from_blobs/poses.csv"), poses_images);
}

}  // namespace
}  // namespace mocap
