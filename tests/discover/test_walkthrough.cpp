// The real-camera walkthrough of docs/operations.md ("From nothing to joint angles on
// real cameras"), executed on simulated cameras exactly as a lab runs it on real ones:
// the scenes are rendered by the simulator and played to `mocap record` / `mocap run` as
// cameras (replay backend), so every step sees only what a lab's cameras would deliver
// and the simulator's truth stays hidden until the last check.
//  1. record a wand and an L-frame, `calibrate-rig` (no targets exist yet);
//  2. record the robot moving with the calibrated rig, `discover`;
//  3. `run --config` with the calibrated rig and the discovered targets and model, its
//     UDP datagrams received here;
//  4. the angles match the simulator's truth (angle_truth.h).
#include <gtest/gtest.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <map>
#include <thread>

#include "angle_truth.h"
#include "client/datagram.h"
#include "tests/support/test_support.h"
#include "tests/support/udp_port.h"

namespace mocap {
namespace {

using test::run_mocap;

// A configuration whose two cameras play `source` (a rendered scene) in lockstep.
std::string camera_config(const test::TempDir& dir, const std::string& name,
                          const std::string& source, const std::string& extra) {
  const std::string path = dir.file(name + ".yaml");
  std::ofstream(path) << "version: 1\ncameras:\n"
                      << "  - {backend: replay, device: " << source << ", trigger: software}\n"
                      << "  - {backend: replay, device: " << source << ", trigger: software}\n"
                      << "pipeline: {pacing: lockstep, realtime: false}\n"
                      << "outputs: {udp: [], iceoryx: false}\n"
                      << extra;
  return path;
}

TEST(Walkthrough, FromNothingToJointAnglesOnSimulatedCameras) {
  test::TempDir dir("walkthrough");
  auto f = [&](const std::string& n) { return dir.file(n); };
  // What the cameras will see.
  ASSERT_EQ(
      run_mocap("simulate --motion wand --frames 150 --out " + f("scene_wand"), 300).exit_code, 0);
  ASSERT_EQ(
      run_mocap("simulate --motion lframe --frames 10 --out " + f("scene_lframe"), 120).exit_code,
      0);
  ASSERT_EQ(run_mocap("simulate --frames 150 --seed 7 --out " + f("scene_robot"), 300).exit_code,
            0);

  // 1. Wand and L-frame recordings (timing is irrelevant to them: recorded fast), then
  //    the rig. No targets are configured: the cameras are recorded before any exist.
  auto rec = run_mocap("record --config " + camera_config(dir, "wand", f("scene_wand"), "") +
                           " --out " + f("wand") + " --rate 1000 --progress-interval 0",
                       120);
  ASSERT_EQ(rec.exit_code, 0) << rec.output;
  EXPECT_FALSE(std::filesystem::exists(f("wand/targets.yaml")));
  rec = run_mocap("record --config " + camera_config(dir, "lframe", f("scene_lframe"), "") +
                      " --out " + f("lframe") + " --rate 1000 --progress-interval 0",
                  120);
  ASSERT_EQ(rec.exit_code, 0) << rec.output;
  // The wand's description is the lab's measurement of its wand.
  auto cal = run_mocap("calibrate-rig " + f("wand") + " --wand " + f("scene_wand/wand.yaml") +
                           " --lframe " + f("lframe") + " --out " + f("rig.yaml"),
                       120);
  ASSERT_EQ(cal.exit_code, 0) << cal.output;
  EXPECT_NE(cal.output.find("ground frame set"), std::string::npos) << cal.output;
  // The report says how the wand balls' centres were found (the rod-side cut).
  EXPECT_NE(test::read_file(f("rig_report/report.yaml")).find("wand_centres: {rod_cut_deg: "),
            std::string::npos);

  // 2. The robot moving, at the cameras' rate, with the calibrated rig; then discover.
  rec = run_mocap("record --config " +
                      camera_config(dir, "robot", f("scene_robot"), "rig: rig.yaml\n") + " --out " +
                      f("robot") + " --progress-interval 0",
                  120);
  ASSERT_EQ(rec.exit_code, 0) << rec.output;
  EXPECT_EQ(test::read_file(f("robot/rig.yaml")), test::read_file(f("rig.yaml")));
  auto disc = run_mocap(
      "discover " + f("robot") + " --out " + f("found") + " --urdf " + f("found/robot.urdf"), 120);
  ASSERT_EQ(disc.exit_code, 0) << disc.output;
  EXPECT_NE(disc.output.find("discovered 3 bodies and 2 joints"), std::string::npos) << disc.output;

  // 3. Live tracking with the results; the angles arrive over UDP. A socket of our own
  // keeps every datagram (a client::UdpReceiver keeps the latest only).
  const test::KeepAllUdpSocket udp(50'000);
  ASSERT_TRUE(udp.ok());
  const std::string run_cfg =
      camera_config(dir, "run", f("scene_robot"),
                    "rig: rig.yaml\ntargets: found/targets.yaml\nmodel: found/model.yaml\n");
  test::RunResult run;
  std::atomic<bool> run_done{false};
  std::thread runner([&] {
    run = run_mocap("run --config " + run_cfg + " --udp 127.0.0.1:" + std::to_string(udp.port()) +
                        " --duration 2 --stats-interval 0",
                    60);
    run_done.store(true, std::memory_order_release);  // `run` is complete
  });
  std::map<std::int64_t, std::int64_t> frame_of_ns;  // truth timestamps -> frames
  auto truth = read_angles_csv(f("scene_robot/gt/angles.csv"));
  ASSERT_TRUE(truth) << truth.error().message;
  for (const AngleRow& r : *truth) frame_of_ns[r.timestamp_ns] = r.frame;
  std::vector<AngleRow> found;
  std::map<std::uint64_t, bool> sequences;
  const auto until = std::chrono::steady_clock::now() + std::chrono::seconds(20);
  std::uint8_t buf[client::kMaxDatagramBytes + 1];
  client::JointsMessage m;
  while (std::chrono::steady_clock::now() < until && sequences.size() < 150) {
    const ssize_t n = udp.receive(buf, sizeof buf);
    if (n <= 0) {
      if (run_done.load(std::memory_order_acquire)) break;  // ended, nothing pending
      continue;
    }
    if (client::decode_datagram(buf, static_cast<std::size_t>(n), m) != client::DecodeStatus::kOk)
      continue;
    if (sequences[m.sequence]) continue;
    sequences[m.sequence] = true;
    const auto fr = frame_of_ns.find(m.capture_ns);
    if (fr == frame_of_ns.end()) continue;
    for (std::uint16_t j = 0; j < m.joint_count; ++j) {
      const client::JointRecord& jr = m.joints[j];
      if (jr.valid == 0) continue;
      AngleRow row;
      row.frame = fr->second;
      row.timestamp_ns = m.capture_ns;
      row.type = jr.type == static_cast<std::uint8_t>(client::JointKind::kHinge) ? JointType::kHinge
                                                                                 : JointType::kBall;
      row.angles_deg = Eigen::Vector3f(jr.a[0], jr.a[1], jr.a[2]).cast<double>() * kDegPerRad;
      row.q_parent_child = Eigen::Quaternionf(jr.q[0], jr.q[1], jr.q[2], jr.q[3]).cast<double>();
      found.push_back(row);
    }
  }
  runner.join();
  ASSERT_EQ(run.exit_code, 0) << run.output;
  EXPECT_GE(sequences.size(), 145U);  // every frame of the recording, UDP on loopback

  // 4. Against the truth: every frame of the recording, both joints.
  test::expect_true_angles(found, f("scene_robot/gt/angles.csv"), 130);
}

}  // namespace
}  // namespace mocap
