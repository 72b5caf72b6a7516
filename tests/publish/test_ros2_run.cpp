// `mocap run --ros2` end to end: the built tracker runs the simulated rig at 100 Hz for
// 2 seconds with UDP to this test and ROS 2 on a DDS domain of its own
// (ROS_DOMAIN_ID); a Cyclone DDS reader with the ROS 2 IDL and names receives
// /joint_states and /tf. Checked: at least 95 % of the frames the UDP datagrams carry
// after the reader matched arrive on both topics, the joint positions are exactly the
// datagrams' angles (frames aligned by capture time: stamp - capture_ns is one constant
// offset), the names are the revolute joints of the URDF the tracker publishes on
// /robot_description (transient local), and the run reports the ros2 counters.
#include <dds/dds.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <chrono>
#include <cstdint>
#include <map>
#include <string>
#include <thread>
#include <vector>

#include "client/datagram.h"
#include "ros2_msgs.h"
#include "tests/support/test_support.h"
#include "tests/support/udp_port.h"

namespace mocap {
namespace {

struct JsRecord {
  std::int64_t stamp_ns = 0;
  std::vector<std::string> names;
  std::vector<double> positions;
};

TEST(Ros2Run, TrackerPublishesEveryFrameOnJointStatesAndTf) {
  const std::uint32_t domain = static_cast<std::uint32_t>(10 + ::getpid() % 80);
  // The UDP side: a socket of our own, every datagram kept.
  const test::KeepAllUdpSocket udp_rx(20'000);
  ASSERT_TRUE(udp_rx.ok());
  // The DDS side.
  const dds_entity_t pp = dds_create_participant(domain, nullptr, nullptr);
  ASSERT_GT(pp, 0);
  dds_qos_t* qos = dds_create_qos();
  dds_qset_reliability(qos, DDS_RELIABILITY_RELIABLE, DDS_SECS(1));
  dds_qset_history(qos, DDS_HISTORY_KEEP_ALL, 0);
  const dds_entity_t js =
      dds_create_reader(pp,
                        dds_create_topic(pp, &sensor_msgs_msg_dds__JointState__desc,
                                         "rt/joint_states", nullptr, nullptr),
                        qos, nullptr);
  const dds_entity_t tf = dds_create_reader(
      pp, dds_create_topic(pp, &tf2_msgs_msg_dds__TFMessage__desc, "rt/tf", nullptr, nullptr), qos,
      nullptr);
  dds_qset_durability(qos, DDS_DURABILITY_TRANSIENT_LOCAL);
  const dds_entity_t desc =
      dds_create_reader(pp,
                        dds_create_topic(pp, &std_msgs_msg_dds__String__desc,
                                         "rt/robot_description", nullptr, nullptr),
                        qos, nullptr);
  dds_delete_qos(qos);
  ASSERT_GT(desc, 0);
  std::string urdf;
  ASSERT_GT(js, 0);
  ASSERT_GT(tf, 0);

  test::TempDir dir("ros2_run");
  const std::string stats = dir.file("stats.json");
  test::RunResult run;
  std::thread tracker([&] {
    run = test::run_command("ROS_DOMAIN_ID=" + std::to_string(domain) + " timeout -s KILL 60 " +
                            test::mocap_binary() +
                            " run --ros2 --duration 2 --rate 100 --loop-frames 4 --no-realtime "
                            "--no-iceoryx --stats-interval 0 --udp 127.0.0.1:" +
                            std::to_string(udp_rx.port()) + " --stats " + stats + " 2>&1");
  });
  std::vector<client::JointsMessage> udp;
  std::vector<JsRecord> states;
  std::size_t tf_count = 0, tf_transforms = 0;
  bool matched = false;
  std::size_t udp_at_match = 0;
  std::uint8_t buf[2048];
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
  bool done = false;
  auto drain_dds = [&] {
    void* samples[32];
    dds_sample_info_t infos[32];
    {
      void* d[1] = {nullptr};
      dds_sample_info_t di[1];
      if (dds_take(desc, d, di, 1, 1) == 1) {
        if (di[0].valid_data) urdf = static_cast<const std_msgs_msg_dds__String_*>(d[0])->data;
        dds_return_loan(desc, d, 1);
      }
    }
    for (;;) {
      for (void*& s : samples) s = nullptr;
      const dds_return_t n = dds_take(js, samples, infos, 32, 32);
      if (n <= 0) break;
      for (int i = 0; i < n; ++i) {
        if (!infos[i].valid_data) continue;
        const auto* m = static_cast<const sensor_msgs_msg_dds__JointState_*>(samples[i]);
        JsRecord r;
        r.stamp_ns = static_cast<std::int64_t>(m->header.stamp.sec) * 1'000'000'000 +
                     m->header.stamp.nanosec;
        for (std::uint32_t k = 0; k < m->name._length; ++k) {
          r.names.emplace_back(m->name._buffer[k]);
          r.positions.push_back(m->position._buffer[k]);
        }
        states.push_back(std::move(r));
      }
      dds_return_loan(js, samples, n);
    }
    for (;;) {
      for (void*& s : samples) s = nullptr;
      const dds_return_t n = dds_take(tf, samples, infos, 32, 32);
      if (n <= 0) break;
      for (int i = 0; i < n; ++i) {
        if (!infos[i].valid_data) continue;
        const auto* m = static_cast<const tf2_msgs_msg_dds__TFMessage_*>(samples[i]);
        ++tf_count;
        tf_transforms += m->transforms._length;
        for (std::uint32_t k = 0; k < m->transforms._length; ++k)
          EXPECT_STREQ(m->transforms._buffer[k].header.frame_id, "mocap");
      }
      dds_return_loan(tf, samples, n);
    }
  };
  while (!done && std::chrono::steady_clock::now() < deadline) {
    const ssize_t n = udp_rx.receive(buf, sizeof buf);
    if (n > 0) {
      client::JointsMessage m;
      if (client::decode_datagram(buf, static_cast<std::size_t>(n), m) == client::DecodeStatus::kOk)
        udp.push_back(m);
    }
    if (!matched) {
      dds_subscription_matched_status_t s1{}, s2{};
      dds_get_subscription_matched_status(js, &s1);
      dds_get_subscription_matched_status(tf, &s2);
      if (s1.current_count > 0 && s2.current_count > 0) {
        matched = true;
        udp_at_match = udp.size();
      }
    }
    drain_dds();
    if (n <= 0 && !udp.empty() && matched) {
      // quiet for 20 ms after data: the run may be over; it ends by itself.
      dds_subscription_matched_status_t s{};
      dds_get_subscription_matched_status(js, &s);
      if (s.current_count == 0) done = true;
    }
  }
  tracker.join();
  drain_dds();
  dds_delete(pp);
  ASSERT_EQ(run.exit_code, 0) << run.output;
  ASSERT_TRUE(matched) << run.output;
  ASSERT_GT(udp.size(), 50u) << run.output;
  // Frames after the reader matched (discovery takes a moment; the sim loop renders first).
  const std::size_t expected = udp.size() - udp_at_match;
  EXPECT_GE(static_cast<double>(states.size()), 0.95 * static_cast<double>(expected))
      << states.size() << " of " << expected;
  EXPECT_GE(static_cast<double>(tf_count), 0.95 * static_cast<double>(expected));
  EXPECT_GT(tf_transforms, 0u);
  ASSERT_FALSE(states.empty());
  // Align: stamp_ns - capture_ns is the same offset for every frame.
  std::map<std::int64_t, const client::JointsMessage*> by_capture;
  for (const auto& m : udp) by_capture[m.capture_ns] = &m;
  std::int64_t offset = 0;
  bool found = false;
  for (const auto& m : udp) {  // the first state's frame: the offset that makes every state match
    const std::int64_t o = states.front().stamp_ns - m.capture_ns;
    std::size_t hits = 0;
    for (const auto& s : states) hits += by_capture.count(s.stamp_ns - o);
    if (hits == states.size()) {
      offset = o;
      found = true;
      break;
    }
  }
  ASSERT_TRUE(found) << "no constant CLOCK_REALTIME offset maps the stamps onto the datagrams";
  std::size_t compared = 0;
  for (const auto& s : states) {
    const client::JointsMessage& m = *by_capture[s.stamp_ns - offset];
    std::size_t k = 0;
    for (std::uint16_t j = 0; j < m.joint_count; ++j) {
      if (m.joints[j].valid == 0) continue;
      const int dofs =
          m.joints[j].type == static_cast<std::uint8_t>(client::JointKind::kHinge) ? 1 : 3;
      for (int c = 0; c < dofs; ++c, ++k) {
        ASSERT_LT(k, s.positions.size());
        EXPECT_EQ(s.positions[k], static_cast<double>(m.joints[j].a[c]));
        if (dofs == 3) {
          const char suffix[] = {'_', static_cast<char>('x' + c), '\0'};
          EXPECT_EQ(s.names[k].substr(s.names[k].size() - 2), suffix);
        }
        ++compared;
      }
    }
    EXPECT_EQ(k, s.positions.size());
  }
  EXPECT_GT(compared, 0u);
  // /robot_description (transient local): the URDF whose revolute joints name the states.
  ASSERT_NE(urdf.find("<robot name=\"mocap_robot\">"), std::string::npos) << urdf.substr(0, 200);
  for (const std::string& n : states.front().names)
    EXPECT_NE(urdf.find("<joint name=\"" + n + "\" type=\"revolute\">"), std::string::npos) << n;
  const std::string json = test::read_file(stats);
  EXPECT_NE(json.find("output_ros2_published"), std::string::npos);
}

}  // namespace
}  // namespace mocap
