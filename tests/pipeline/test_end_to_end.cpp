// End to end over a real socket: simulated cameras -> pipeline -> UdpPublisher ->
// 127.0.0.1 -> client::UdpReceiver, as a motor controller would consume it.
//   * Every datagram the client accepts carries exactly the message the pipeline made
//     (compared field by field with an in-process recording of the same run).
//   * The received angles match the simulator's ground truth. Tolerance (the tracker's
//     accuracy on this scene, as in test_pipeline): ball joint median error <= 1 deg and
//     95th percentile <= 5 deg; hinge motion within 2 deg of the truth in >= 95 % of the
//     frames after removing the constant zero offset of the hinge convention.
//   * Frames are dropped on purpose (a sink that stalls 30 ms on some frames at 200 Hz):
//     the client's sequence gaps equal the pipeline's sequence-level drop counters (minus
//     the frames lost before the first and after the last received one), and
//     triggered = published + dropped.
// Short run: 150 frames at 200 Hz (~0.75 s).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <thread>
#include <vector>

#include "client/udp_receiver.h"
#include "pipeline/publish/udp_publisher.h"
#include "pipeline/stats_report.h"
#include "sim/simulate.h"
#include "tests/pipeline/pipeline_fixture.h"

namespace mocap::pipeline {
namespace {

using test::counter;
using test::RecordingSink;
using test::shared_loop;
using test::SimRigFixture;

// Stalls the publish thread on every 25th frame (a slow consumer of the pipeline).
class StallingSink final : public publish::OutputSink {
 public:
  const char* name() const noexcept override { return "stalling"; }
  publish::OutputCounters counters() const noexcept override { return {}; }
  bool publish(const publish::FrameResult& f) noexcept override {
    if (f.joints.sequence % 25 == 10) std::this_thread::sleep_for(std::chrono::milliseconds(30));
    return true;
  }
};

TEST(EndToEnd, SimCamerasToUdpClientWithGroundTruthAndGapAccounting) {
  auto rx = client::UdpReceiver::create("127.0.0.1:0");
  ASSERT_TRUE(rx.ok()) << rx.error().message;
  auto udp = publish::UdpPublisher::create({"127.0.0.1:" + std::to_string(rx->port())});
  ASSERT_TRUE(udp.ok()) << udp.error().message;
  test::UdpPublisherSink udp_sink(std::move(udp).value());
  StallingSink stall;
  RecordingSink record(400);

  SimRigFixture rig;
  PipelineOptions opt = test::test_options();
  opt.max_frames = 150;
  opt.trigger_rate_hz = 200.0;
  opt.catch_up_ns = 0;  // the newest frame first: the stalls drop frames (the gaps tested)
  auto p = Pipeline::create(rig.processor(), rig.cameras(), {&stall, &record, &udp_sink}, opt);
  ASSERT_TRUE(p.ok()) << p.error().message;
  ASSERT_TRUE((*p)->start().ok());

  // The controller side: take the newest message every ~0.5 ms.
  std::vector<client::JointsMessage> seen;
  seen.reserve(400);
  const auto poll_once = [&] {
    const std::uint64_t before = rx->counters().accepted;
    rx->wait(std::chrono::microseconds(500));
    if (rx->counters().accepted != before) seen.push_back(rx->latest());
  };
  const auto until = std::chrono::steady_clock::now() + std::chrono::seconds(30);
  while (!(*p)->finished() && std::chrono::steady_clock::now() < until) poll_once();
  (*p)->stop();
  for (int i = 0; i < 100; ++i) poll_once();  // the last datagrams in flight
  const PipelineStats st = (*p)->stats();
  const std::string report = format_pipeline_stats(st);

  // Delivery: every published message reached the client, nothing else did.
  ASSERT_EQ(st.triggered, 150u);
  ASSERT_GT(record.count(), 20u) << report;
  const client::ReceiverCounters& c = rx->counters();
  EXPECT_EQ(c.accepted, st.published) << report;
  EXPECT_EQ(c.rejected_total(), 0u);
  EXPECT_EQ(c.stale, 0u);

  // Gaps: frames were dropped (the stalls), and the client's gaps are exactly the
  // pipeline's sequence-level drops between the first and the last frame it received
  // (the pipeline also counts frames lost before the first published one, e.g. skipped
  // by a detector that a loaded machine delayed at start, and after the last).
  const std::uint64_t dropped = counter(st, "frames_dropped");
  // The stalls drop frames at publish; on a machine slower than the trigger (TSan) the
  // newest-first stages before it drop them first. Either way there are gaps to account.
  EXPECT_GT(dropped, 0u) << report;
  EXPECT_EQ(dropped, counter(st, "frames_unpaired") + counter(st, "identify_skipped") +
                         counter(st, "identify_no_slot") + counter(st, "publish_skipped"));
  const std::uint64_t first = record[0].sequence;
  const std::uint64_t last = record[record.count() - 1].sequence;
  ASSERT_LE(first + (st.triggered - 1 - last), dropped) << report;
  EXPECT_EQ(c.dropped_frames, dropped - first - (st.triggered - 1 - last)) << report;
  EXPECT_EQ(st.triggered, st.published + dropped) << report;
  EXPECT_EQ((*p)->health().frames_dropped, dropped);

  // Fidelity and ground truth on every message the controller saw.
  ASSERT_GT(seen.size(), 10u);
  const sim::SimScene& scene = shared_loop()->scene();
  std::vector<double> ball_err_deg, hinge_offset_rad;
  std::size_t r = 0;
  for (const client::JointsMessage& m : seen) {
    while (r < record.count() && record[r].sequence < m.sequence) ++r;
    ASSERT_LT(r, record.count());
    const client::JointsMessage& want = record[r];
    ASSERT_EQ(m.sequence, want.sequence);
    EXPECT_EQ(m.capture_ns, want.capture_ns);
    EXPECT_GE(m.publish_ns, m.capture_ns);
    EXPECT_EQ(m.flags, want.flags);
    ASSERT_EQ(m.joint_count, scene.joints_true.joints.size());
    const sim::SceneState& truth =
        shared_loop()->state(shared_loop()->frame_of_sequence(m.sequence));
    for (std::size_t j = 0; j < m.joint_count; ++j) {
      const client::JointRecord& got = m.joints[j];
      EXPECT_EQ(got.valid, want.joints[j].valid);
      for (int k = 0; k < 3; ++k) EXPECT_EQ(got.a[k], want.joints[j].a[k]);
      if (got.valid == 0) continue;
      const JointSpec& js = scene.joints_true.joints[j];
      const Vec3 t =
          sim::joint_angles_rad(js, truth.T_world_body[static_cast<std::size_t>(js.parent_index)],
                                truth.T_world_body[static_cast<std::size_t>(js.child_index)]);
      if (js.type == JointType::kHinge) {
        hinge_offset_rad.push_back(std::remainder(static_cast<double>(got.a[0]) - t[0], 2 * M_PI));
        continue;
      }
      for (int k = 0; k < 3; ++k) {
        const double d = std::remainder(static_cast<double>(got.a[k]) - t[k], 2 * M_PI);
        ball_err_deg.push_back(std::abs(d) * 180.0 / M_PI);
      }
    }
  }
  ASSERT_FALSE(ball_err_deg.empty());
  std::sort(ball_err_deg.begin(), ball_err_deg.end());
  EXPECT_LE(ball_err_deg[ball_err_deg.size() / 2], 1.0) << "median ball angle error (deg)";
  EXPECT_LE(ball_err_deg[ball_err_deg.size() * 95 / 100], 5.0) << "95th percentile (deg)";
  ASSERT_FALSE(hinge_offset_rad.empty());
  std::vector<double> sorted = hinge_offset_rad;
  std::sort(sorted.begin(), sorted.end());
  const double offset = sorted[sorted.size() / 2];
  std::size_t hinge_ok = 0;
  for (double o : hinge_offset_rad)
    hinge_ok += std::abs(std::remainder(o - offset, 2 * M_PI)) <= 2.0 * M_PI / 180.0;
  EXPECT_GE(hinge_ok * 20, hinge_offset_rad.size() * 19) << "hinge within 2 deg";
}

}  // namespace
}  // namespace mocap::pipeline
