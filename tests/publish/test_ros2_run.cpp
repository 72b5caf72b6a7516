// `mocap run --ros2` end to end: the built tracker runs the simulated rig at 100 Hz for
// 2 seconds with UDP to this test and ROS 2 on a DDS domain of its own
// (ROS_DOMAIN_ID); a Cyclone DDS reader with the ROS 2 IDL and names receives
// /joint_states and /tf. Checked: at least 95 % of the frames the UDP datagrams carry
// after the reader matched arrive on both topics, the joint positions are exactly the
// datagrams' angles (frames aligned by capture time: stamp - capture_ns is one constant
// offset), the names are the revolute joints of the URDF the tracker publishes on
// /robot_description (transient local), and the run reports the ros2 counters.
// The 2027-01 additions (the acceptance of issue 30 item 5): every /joint_states entry has
// a velocity (rad/s; NaN only while a rate is not known yet, and most are known), every
// body /tf names gets /mocap/<body>/pose messages (readers made as soon as /tf names the
// bodies) equal to its /tf transforms of the same frames, for at least 95 % of the frames
// after they matched, and /mocap/unlabeled_markers arrives with every frame.
#include <dds/dds.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <array>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <map>
#include <set>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include "client/datagram.h"
#include "pipeline/publish/ros2/ros2_mapping.h"
#include "ros2_msgs.h"
#include "tests/support/test_support.h"
#include "tests/support/udp_port.h"

namespace mocap {
namespace {

struct JsRecord {
  std::int64_t stamp_ns = 0;
  std::vector<std::string> names;
  std::vector<double> positions;
  std::vector<double> velocities;
};

// A pose as /tf and /mocap/<body>/pose carry it: stamp, x y z, qw qx qy qz.
using PoseKey = std::pair<std::string, std::int64_t>;  // body, stamp
using PoseValues = std::array<double, 7>;

std::int64_t stamp_of(const builtin_interfaces_msg_dds__Time_& t) {
  return static_cast<std::int64_t>(t.sec) * 1'000'000'000 + t.nanosec;
}

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
  dds_qset_durability(qos, DDS_DURABILITY_VOLATILE);
  const dds_entity_t cloud =
      dds_create_reader(pp,
                        dds_create_topic(pp, &sensor_msgs_msg_dds__PointCloud2__desc,
                                         "rt/mocap/unlabeled_markers", nullptr, nullptr),
                        qos, nullptr);
  ASSERT_GT(desc, 0);
  ASSERT_GT(cloud, 0);
  std::map<std::string, dds_entity_t> pose_readers;  // body -> reader, once /tf names it
  std::map<PoseKey, PoseValues> tf_poses, pose_msgs;
  std::size_t clouds = 0;
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
        EXPECT_EQ(m->velocity._length, m->name._length);
        for (std::uint32_t k = 0; k < m->name._length; ++k) {
          r.names.emplace_back(m->name._buffer[k]);
          r.positions.push_back(m->position._buffer[k]);
          if (k < m->velocity._length) r.velocities.push_back(m->velocity._buffer[k]);
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
        for (std::uint32_t k = 0; k < m->transforms._length; ++k) {
          const auto& x = m->transforms._buffer[k];
          EXPECT_STREQ(x.header.frame_id, "mocap");
          const auto& t = x.transform.translation;
          const auto& q = x.transform.rotation;
          tf_poses[{x.child_frame_id, stamp_of(x.header.stamp)}] = {t.x, t.y, t.z, q.w,
                                                                    q.x, q.y, q.z};
          if (pose_readers.count(x.child_frame_id) == 0) {
            const std::string topic =
                "rt/mocap/" + publish::ros2::topic_token(x.child_frame_id) + "/pose";
            pose_readers[x.child_frame_id] =
                dds_create_reader(pp,
                                  dds_create_topic(pp, &geometry_msgs_msg_dds__PoseStamped__desc,
                                                   topic.c_str(), nullptr, nullptr),
                                  qos, nullptr);
          }
        }
      }
      dds_return_loan(tf, samples, n);
    }
    for (const auto& [body, reader] : pose_readers) {
      for (;;) {
        for (void*& s : samples) s = nullptr;
        const dds_return_t n = dds_take(reader, samples, infos, 32, 32);
        if (n <= 0) break;
        for (int i = 0; i < n; ++i) {
          if (!infos[i].valid_data) continue;
          const auto* m = static_cast<const geometry_msgs_msg_dds__PoseStamped_*>(samples[i]);
          EXPECT_STREQ(m->header.frame_id, "mocap");
          const auto& t = m->pose.position;
          const auto& q = m->pose.orientation;
          pose_msgs[{body, stamp_of(m->header.stamp)}] = {t.x, t.y, t.z, q.w, q.x, q.y, q.z};
        }
        dds_return_loan(reader, samples, n);
      }
    }
    for (;;) {
      for (void*& s : samples) s = nullptr;
      const dds_return_t n = dds_take(cloud, samples, infos, 32, 32);
      if (n <= 0) break;
      for (int i = 0; i < n; ++i) {
        if (!infos[i].valid_data) continue;
        const auto* m = static_cast<const sensor_msgs_msg_dds__PointCloud2_*>(samples[i]);
        EXPECT_EQ(m->point_step, 12u);
        EXPECT_EQ(m->data._length, 12u * m->width);
        ++clouds;
      }
      dds_return_loan(cloud, samples, n);
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
  dds_delete_qos(qos);
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
  EXPECT_GE(static_cast<double>(clouds), 0.95 * static_cast<double>(expected)) << clouds;
  // /mocap/<body>/pose: every body /tf named; each pose is its /tf transform of that frame,
  // and from its first pose on, at least 95 % of the body's /tf frames have one.
  ASSERT_FALSE(pose_readers.empty());
  for (const auto& [body, reader] : pose_readers) {
    std::int64_t first = -1;
    std::size_t poses = 0, frames = 0;
    for (const auto& [key, values] : pose_msgs) {
      if (key.first != body) continue;
      if (first < 0 || key.second < first) first = key.second;
      ++poses;
      const auto it = tf_poses.find(key);
      ASSERT_NE(it, tf_poses.end()) << body << ": a pose without its /tf frame";
      EXPECT_EQ(it->second, values) << body;
    }
    EXPECT_GT(poses, 0u) << "no /mocap/" << body << "/pose";
    for (const auto& [key, values] : tf_poses) frames += key.first == body && key.second >= first;
    EXPECT_GE(static_cast<double>(poses), 0.95 * static_cast<double>(frames)) << body;
  }
  // JointState.velocity for every valid joint: one per entry; known for most entries.
  std::size_t known = 0, entries = 0;
  for (const auto& s : states) {
    EXPECT_EQ(s.velocities.size(), s.positions.size());
    for (const double v : s.velocities) known += std::isfinite(v) ? 1 : 0;
    entries += s.velocities.size();
  }
  EXPECT_GE(static_cast<double>(known), 0.5 * static_cast<double>(entries));
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
