// Design: what the camera-node cluster tests (test_node_cluster.cpp, 8 cameras over 2
// nodes; test_node_cluster_wide.cpp, 12 cameras over 2 nodes) share, one home each: the
// test's own folder, the configurations of the nodes and of the central (written into
// that folder as node0.yaml, node1.yaml, central.yaml), the single-process reference
// (single.yaml), running the two nodes and the central as processes, and the joint angles
// the central published over UDP. What differs between the tests (the recording, the
// cameras per node, the DDS domain, the central's pipeline keys) is a parameter.
#pragma once

#include <gtest/gtest.h>
#include <signal.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <map>
#include <string>
#include <thread>
#include <vector>

#include "client/datagram.h"
#include "tests/support/test_support.h"
#include "tests/support/udp_port.h"

namespace mocap::test::node_cluster {

// capture_ns -> every joint's a[3] (NaN where the joint is not valid).
using Angles = std::map<std::int64_t, std::vector<float>>;

struct Published {
  Angles angles;
  int datagrams = 0;
};

// Adds one datagram (n bytes of buf) to p when it decodes.
inline void add_datagram(const std::uint8_t* buf, ssize_t n, Published& p) {
  client::JointsMessage m;
  if (n <= 0 ||
      client::decode_datagram(buf, static_cast<std::size_t>(n), m) != client::DecodeStatus::kOk)
    return;
  ++p.datagrams;
  std::vector<float>& a = p.angles[m.capture_ns];
  for (int j = 0; j < m.joint_count; ++j)
    for (float v : m.joints[j].a) a.push_back(m.joints[j].valid ? v : NAN);
}

// Adds the datagrams received on sock to p until none comes within the socket's timeout.
inline void drain_into(const KeepAllUdpSocket& sock, Published& p) {
  std::uint8_t buf[client::kMaxDatagramBytes + 16];
  for (;;) {
    const ssize_t n = sock.receive(buf, sizeof buf);
    if (n <= 0) break;
    add_datagram(buf, n, p);
  }
}

// The datagrams received so far on sock.
inline Published drain(const KeepAllUdpSocket& sock) {
  Published p;
  drain_into(sock, p);
  return p;
}

// Adds the datagrams received on sock to p until it holds `datagrams` of them (true) or
// timeout_s passed (false): the event a cluster test waits for, instead of a wall-clock
// guess at how fast the processes start and run on a loaded machine.
inline bool receive_until(const KeepAllUdpSocket& sock, Published& p, int datagrams,
                          double timeout_s) {
  std::uint8_t buf[client::kMaxDatagramBytes + 16];
  const auto deadline = std::chrono::steady_clock::now() +
                        std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                            std::chrono::duration<double>(timeout_s));
  while (p.datagrams < datagrams) {
    if (std::chrono::steady_clock::now() > deadline) return false;
    add_datagram(buf, sock.receive(buf, sizeof buf), p);
  }
  return true;
}

// Every frame of ref published in got, with the same valid joints and angles within
// tolerance_rad; more than min_compared angles compared. context: printed on a failure.
inline void expect_same_angles(const Angles& ref, const Angles& got, double tolerance_rad,
                               int min_compared, const std::string& context) {
  ASSERT_EQ(got.size(), ref.size()) << context;
  double worst = 0.0;
  int compared = 0;
  for (const auto& [capture_ns, a] : ref) {
    const auto it = got.find(capture_ns);
    ASSERT_NE(it, got.end()) << "frame at " << capture_ns << " not published\n" << context;
    ASSERT_EQ(it->second.size(), a.size());
    for (std::size_t i = 0; i < a.size(); ++i) {
      ASSERT_EQ(std::isnan(a[i]), std::isnan(it->second[i])) << "joint validity differs";
      if (std::isnan(a[i])) continue;
      worst = std::max(worst, static_cast<double>(std::fabs(a[i] - it->second[i])));
      ++compared;
    }
  }
  EXPECT_GT(compared, min_compared);
  EXPECT_LE(worst, tolerance_rad);
}

// The current test's own empty folder: TempDir()/<prefix>_<pid>_<test name>.
inline std::string fresh_test_dir(const std::string& prefix) {
  const std::string name = ::testing::UnitTest::GetInstance()->current_test_info()->name();
  const std::string dir =
      ::testing::TempDir() + prefix + "_" + std::to_string(::getpid()) + "_" + name;
  EXPECT_EQ(run_command("rm -rf '" + dir + "' && mkdir -p '" + dir + "'").exit_code, 0) << dir;
  return dir;
}

// The keys of a tracker on `recording` (its targets and true model) publishing over UDP
// to 127.0.0.1:port only; pipeline: the pipeline section's keys besides realtime and
// lock_memory (both false).
inline std::string tracker_keys(const std::string& recording, const std::string& pipeline,
                                int port) {
  return "targets: " + recording + "/targets.yaml\nmodel: " + recording +
         "/gt/model_true.yaml\npipeline: {" + pipeline +
         ", realtime: false, lock_memory: false}\noutputs: {udp: [127.0.0.1:" +
         std::to_string(port) + "], iceoryx: false}\n";
}

// Two nodes of cameras_per_node replay cameras each (node n: cameras n * cameras_per_node
// onwards of the recording) and the central's node cameras, all of them.
struct Cluster {
  std::string dir;        // where the configurations go (fresh_test_dir())
  std::string recording;  // the recording the nodes replay
  std::string node_name;  // node n is named node_name + n
  int cameras_per_node = 4;
  int domain_id = 1;
  std::string node_pipeline = "realtime: false";  // the nodes' pipeline keys
  std::string node_trigger = "central";           // the nodes' cameras' trigger
  std::string central_trigger;                    // the central cameras' (empty: none given)
  // How long the central waits for a node's frame before it is missing.
  int timeout_ms = 5000;
  // Node n's further `node:` keys (e.g. ", detect_threads: 1"); none past the list's end.
  std::vector<std::string> node_keys;

  static constexpr int kNodes = 2;

  void write(const std::string& name, const std::string& text) const {
    write_file(dir + "/" + name, text);
  }
  // node0.yaml, node1.yaml and central.yaml (its node section, rig and cameras, then
  // central_keys).
  void write_configs(const std::string& central_keys) const {
    for (int n = 0; n < kNodes; ++n) {
      const auto un = static_cast<std::size_t>(n);
      std::string y = "node: {name: " + node_name + std::to_string(n) +
                      ", domain_id: " + std::to_string(domain_id) +
                      (un < node_keys.size() ? node_keys[un] : "") + "}\npipeline: {" +
                      node_pipeline + "}\ncameras:\n";
      for (int c = cameras_per_node * n; c < cameras_per_node * (n + 1); ++c)
        y += "  - {backend: replay, device: " + recording + ", camera: cam" + std::to_string(c) +
             ", trigger: " + node_trigger + "}\n";
      write("node" + std::to_string(n) + ".yaml", y);
    }
    std::string y = "node: {domain_id: " + std::to_string(domain_id) +
                    ", wait_s: 20, timeout_ms: " + std::to_string(timeout_ms) +
                    "}\nrig: " + recording + "/rig.yaml\ncameras:\n";
    for (int c = 0; c < kNodes * cameras_per_node; ++c)
      y += "  - {backend: node, device: " + node_name + std::to_string(c / cameras_per_node) +
           "/cam" + std::to_string(c) +
           (central_trigger.empty() ? "" : ", trigger: " + central_trigger) + "}\n";
    write("central.yaml", y + central_keys);
  }

  // The reference: the recording's cameras replayed by one process (single.yaml:
  // tracker_keys after the cameras), `mocap run` until the replay ends.
  RunResult run_single_process(const std::string& tracker) const {
    std::string single = "cameras:\n";
    for (int c = 0; c < kNodes * cameras_per_node; ++c)
      single += "  - {backend: replay, device: " + recording + ", trigger: software}\n";
    write("single.yaml", single + tracker);
    return run_mocap("run --config '" + dir + "/single.yaml' --stats-interval 0", 120);
  }

  // Both nodes in the background (node 1's pid in node1.pid), the central `mocap
  // <central_args>` in the foreground, all in dir (the central under a 120 s bound), on a
  // thread of their own while `during` runs on the caller's: it may kill_node1() and
  // restart_node1() when the events it waits for came. The output: the central's log,
  // node 0's, then node 1's (the restarted one's when node 1 was restarted).
  RunResult run(
      const std::string& central_args, const std::function<void()>& during = [] {}) const {
    const std::string m = mocap_binary();
    const std::string cmd =
        "cd '" + dir + "' && { " + m +
        " node --config node0.yaml --duration 120 > node0.log 2>&1 & " + m +
        " node --config node1.yaml --duration 120 > node1.log 2>&1 & echo $! > node1.pid; }; " +
        "timeout 120 " + m + " " + central_args +
        " > central.log 2>&1; rc=$?; [ -f node1b.pid ] && kill $(cat node1b.pid); wait; "
        "sleep 0.5; cat central.log node0.log; "
        "if [ -f node1b.log ]; then cat node1b.log; else cat node1.log; fi; exit $rc";
    RunResult r;
    std::thread central([&] { r = run_command(cmd); });
    during();
    central.join();
    // A restart that came after the central ended (its wait timed out) ends here too.
    run_command("[ -f '" + dir + "/node1b.pid' ] && kill $(cat '" + dir +
                "/node1b.pid') 2>/dev/null");
    return r;
  }
  // SIGKILLs node 1 (started by run()).
  void kill_node1() const {
    const std::string pid = read_file(dir + "/node1.pid");
    ASSERT_FALSE(pid.empty()) << dir << "/node1.pid";
    ::kill(static_cast<pid_t>(std::stol(pid)), SIGKILL);
  }
  // Starts node 1 again (for at most 20 s; its log in node1b.log, its pid in node1b.pid).
  void restart_node1() const {
    run_command("cd '" + dir + "' && { " + mocap_binary() +
                " node --config node1.yaml --duration 20 > node1b.log 2>&1 & echo $! > "
                "node1b.pid; }");
  }

  // The central's `mocap record --blobs ... --out blobrec` (its run r) wrote every one of
  // `frames` frames, and the blob recording tracks (into from_blobs/) to the poses of the
  // image recording it was detected from (into from_images/).
  void expect_blob_recording_tracks_as_images(const RunResult& r, int frames) const {
    ASSERT_EQ(r.exit_code, 0) << r.output;
    EXPECT_NE(r.output.find(std::to_string(frames) + " frames triggered, " +
                            std::to_string(frames) + " written, 0 not written"),
              std::string::npos)
        << r.output;
    const std::string targets = " --targets " + recording + "/targets.yaml --quiet";
    const RunResult a =
        run_mocap("track " + recording + targets + " --out '" + dir + "/from_images'", 120);
    ASSERT_EQ(a.exit_code, 0) << a.output;
    const RunResult b =
        run_mocap("track '" + dir + "/blobrec'" + targets + " --out '" + dir + "/from_blobs'", 120);
    ASSERT_EQ(b.exit_code, 0) << b.output;
    const std::string poses_images = read_file(dir + "/from_images/poses.csv");
    EXPECT_GT(poses_images.size(), 1000u);
    EXPECT_EQ(read_file(dir + "/from_blobs/poses.csv"), poses_images);
  }
};

}  // namespace mocap::test::node_cluster
