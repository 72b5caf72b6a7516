// The ROS 2 output end to end in one process: the registry's "ros2" sink publishes into
// a DDS domain of its own (domain_id option, unique per test run), and a Cyclone DDS
// reader written against the same ROS 2 IDL and ROS 2 names (rt/joint_states,
// rt/tf, rt/robot_description; sensor_msgs::msg::dds_::JointState_ ...) receives and
// checks every message: the DOF names of the URDF (hinge "J", ball "J_x/_y/_z"), the
// positions equal to the datagram's float angles, the velocities its rates (NaN while
// not known), invalid joints left out, one
// transform per body found (parent "mocap", metres, x y z w), the stamp on
// CLOCK_REALTIME. A reader that never takes does not slow publish() (drops counted).
// DDS that cannot start gives one notice line and no sink (the tracker runs on). A
// 32-body robot arrives whole. Also: the pure mapping (names, ROS_DOMAIN_ID parsing, stamps).
#include <dds/dds.h>
#include <gtest/gtest.h>
#include <time.h>

#include <chrono>
#include <cmath>
#include <cstdlib>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "pipeline/publish/output_registry.h"
#include "pipeline/publish/ros2/ros2_mapping.h"
#include "ros2_msgs.h"
#include "tests/publish/ros2_test_reader.h"

namespace mocap::publish {
namespace {

using namespace ros2_test;  // Reader, take_all, test_domain, now_ns, make_sink
using Fixture = ArmFixture;

void fill(FrameResult& f, std::uint64_t seq) {
  f = FrameResult{};
  f.joints.sequence = seq;
  f.joints.capture_ns = now_ns(CLOCK_MONOTONIC);
  f.joints.joint_count = 2;
  f.joints.joints[0].type = 1;
  f.joints.joints[0].valid = 1;
  for (int k = 0; k < 3; ++k)
    f.joints.joints[0].a[k] = 0.1f * static_cast<float>(seq) + 0.01f * static_cast<float>(k);
  f.joints.joints[1].valid = seq % 3 == 0 ? 0 : 1;  // every third frame: elbow invalid
  f.joints.joints[1].a[0] = -0.5f + 0.001f * static_cast<float>(seq);
  // Rates: the shoulder's known from frame 3 on, the elbow's always when valid.
  f.joints.rates[0].valid = seq >= 3 ? 1 : 0;
  for (int k = 0; k < 3; ++k)
    f.joints.rates[0].rate_rad_s[k] = seq >= 3 ? 10.0f + static_cast<float>(k) : 0.0f;
  f.joints.rates[1].valid = 1;
  f.joints.rates[1].rate_rad_s[0] = -0.25f * static_cast<float>(seq);
  f.body_count = 3;
  for (int b = 0; b < 3; ++b) {
    f.bodies[b].found = (b == 2 && seq % 3 == 0) ? 0 : 1;
    f.bodies[b].t_world_body_mm = {100.0 * b + static_cast<double>(seq), -20.0, 1500.0};
    const double h = 0.05 * static_cast<double>(seq);
    f.bodies[b].q_world_body = {std::cos(h), 0.0, 0.0, std::sin(h)};
  }
}

TEST(Ros2Mapping, NamesAsTheUrdfAndDomainAndStamp) {
  Fixture fx;
  const auto dofs = ros2::joint_dofs(fx.model, 32);
  ASSERT_EQ(dofs.size(), 4u);
  EXPECT_EQ(dofs[0].name, "shoulder_x");
  EXPECT_EQ(dofs[1].name, "shoulder_y");
  EXPECT_EQ(dofs[2].name, "shoulder_z");
  EXPECT_EQ(dofs[2].component, 2);
  EXPECT_EQ(dofs[3].name, "elbow");
  EXPECT_EQ(dofs[3].joint, 1);
  EXPECT_EQ(*ros2::parse_domain_id(nullptr), 0u);
  EXPECT_EQ(*ros2::parse_domain_id(""), 0u);
  EXPECT_EQ(*ros2::parse_domain_id("42"), 42u);
  for (const char* bad : {"-1", "233", "abc", "4 2", "1000"}) {
    auto e = ros2::parse_domain_id(bad);
    ASSERT_FALSE(e.ok()) << bad;
    EXPECT_EQ(e.error().message.rfind("ROS_DOMAIN_ID: '", 0), 0u) << e.error().message;
  }
  const ros2::Stamp s = ros2::to_stamp(1'500'000'000, 2'000'000'001);
  EXPECT_EQ(s.sec, 3);
  EXPECT_EQ(s.nanosec, 500'000'001u);
  const std::int64_t off = ros2::realtime_offset_ns();
  EXPECT_LT(std::llabs(now_ns(CLOCK_MONOTONIC) + off - now_ns(CLOCK_REALTIME)), 5'000'000);
}

TEST(Ros2Output, BadDomainIsOneLineNamingTheVariable) {
  ::setenv("ROS_DOMAIN_ID", "x7", 1);
  auto e = check_outputs({{"ros2", {"true"}, "--ros2", {}}});
  ::unsetenv("ROS_DOMAIN_ID");
  ASSERT_FALSE(e.ok());
  EXPECT_EQ(e.error().message, "ROS_DOMAIN_ID: 'x7': expected an integer in 0..232");
  // The configuration's outputs.ros2.domain_id wins over the environment.
  e = check_outputs({{"ros2", {"true"}, "m.yaml: outputs.ros2", {{"domain_id", "233"}}}});
  ASSERT_FALSE(e.ok());
  EXPECT_EQ(e.error().message,
            "m.yaml: outputs.ros2: domain_id: expected an integer in 0..232, got '233'");
  EXPECT_FALSE(check_outputs({{"ros2", {"perhaps"}, "--ros2", {}}}).ok());
}

TEST(Ros2Output, MissingDdsIsOneNoticeAndNoSink) {
  // A DDS configuration naming a network interface that does not exist: the participant
  // cannot be created, as on a machine without usable DDS networking.
  ::setenv("CYCLONEDDS_URI",
           "<CycloneDDS><Domain><General><Interfaces><NetworkInterface name=\"nosuchif0\"/>"
           "</Interfaces></General></Domain></CycloneDDS>",
           1);
  Fixture fx;
  OutputContext ctx;
  ctx.targets = &fx.targets;
  auto outs = create_outputs(
      {{"ros2", {"true"}, "--ros2", {{"domain_id", std::to_string(test_domain(2))}}}}, ctx);
  ::unsetenv("CYCLONEDDS_URI");
  ASSERT_TRUE(outs.ok()) << outs.error().message;
  EXPECT_TRUE(outs->sinks.empty());
  ASSERT_EQ(outs->notices.size(), 1u);
  EXPECT_EQ(outs->notices[0].rfind("ros2: DDS unavailable (dds_create_participant: ", 0), 0u)
      << outs->notices[0];
  EXPECT_EQ(outs->notices[0].find('\n'), std::string::npos);
}

TEST(Ros2Output, ReaderReceivesEveryMessageWithRos2NamesAndValues) {
  Fixture fx;
  const std::uint32_t domain = test_domain(0);
  Reader reader(domain);
  ASSERT_TRUE(reader.ok());
  auto sink = make_sink(domain, fx.targets, &fx.model);
  ASSERT_NE(sink, nullptr);
  ASSERT_TRUE(reader.wait_matched());
  std::this_thread::sleep_for(std::chrono::milliseconds(200));  // writer side matches too
  constexpr int kFrames = 30;
  std::vector<FrameResult> sent(kFrames + 1);
  for (int s = 1; s <= kFrames; ++s) {
    fill(sent[static_cast<std::size_t>(s)], static_cast<std::uint64_t>(s));
    ASSERT_TRUE(sink->publish(sent[static_cast<std::size_t>(s)]));
    std::this_thread::sleep_for(std::chrono::milliseconds(3));  // 333 Hz: no queue drops
  }
  for (int i = 0; i < 300 && sink->counters().published < kFrames; ++i)
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  EXPECT_EQ(sink->counters().published, static_cast<std::uint64_t>(kFrames));
  EXPECT_EQ(sink->counters().dropped, 0u);
  EXPECT_EQ(sink->counters().failures, 0u);
  std::this_thread::sleep_for(std::chrono::milliseconds(200));

  std::vector<void*> js_loans, tf_loans, d_loans;
  const auto js = take_all<sensor_msgs_msg_dds__JointState_>(reader.js_, js_loans);
  const auto tf = take_all<tf2_msgs_msg_dds__TFMessage_>(reader.tf_, tf_loans);
  ASSERT_EQ(js.size(), static_cast<std::size_t>(kFrames));
  ASSERT_EQ(tf.size(), static_cast<std::size_t>(kFrames));
  const std::int64_t real_now = now_ns(CLOCK_REALTIME);
  for (int s = 1; s <= kFrames; ++s) {
    const FrameResult& f = sent[static_cast<std::size_t>(s)];
    const sensor_msgs_msg_dds__JointState_& m = *js[static_cast<std::size_t>(s - 1)];
    const bool elbow = f.joints.joints[1].valid != 0;
    ASSERT_EQ(m.name._length, elbow ? 4u : 3u) << s;
    ASSERT_EQ(m.position._length, m.name._length);
    ASSERT_EQ(m.velocity._length, m.name._length);  // rad/s, NaN while not known
    for (int k = 0; k < 3; ++k) {
      if (s >= 3) {
        EXPECT_EQ(m.velocity._buffer[k], 10.0 + k) << s;
      } else {
        EXPECT_TRUE(std::isnan(m.velocity._buffer[k])) << s;
      }
    }
    if (elbow) {
      EXPECT_EQ(m.velocity._buffer[3], static_cast<double>(-0.25f * static_cast<float>(s)));
    }
    EXPECT_STREQ(m.name._buffer[0], "shoulder_x");
    EXPECT_STREQ(m.name._buffer[1], "shoulder_y");
    EXPECT_STREQ(m.name._buffer[2], "shoulder_z");
    for (int k = 0; k < 3; ++k)  // exactly the datagram's float angles
      EXPECT_EQ(m.position._buffer[k], static_cast<double>(f.joints.joints[0].a[k]));
    if (elbow) {
      EXPECT_STREQ(m.name._buffer[3], "elbow");
      EXPECT_EQ(m.position._buffer[3], static_cast<double>(f.joints.joints[1].a[0]));
    }
    const std::int64_t stamp =
        static_cast<std::int64_t>(m.header.stamp.sec) * 1'000'000'000 + m.header.stamp.nanosec;
    EXPECT_LT(real_now - stamp, 10'000'000'000) << "stamp on CLOCK_REALTIME";
    EXPECT_GT(real_now - stamp, 0);

    const tf2_msgs_msg_dds__TFMessage_& t = *tf[static_cast<std::size_t>(s - 1)];
    const bool forearm = f.bodies[2].found != 0;
    ASSERT_EQ(t.transforms._length, forearm ? 3u : 2u) << s;
    const char* names[] = {"torso", "upper_arm", "forearm"};
    for (std::uint32_t b = 0; b < t.transforms._length; ++b) {
      const geometry_msgs_msg_dds__TransformStamped_& x = t.transforms._buffer[b];
      EXPECT_STREQ(x.header.frame_id, "mocap");
      EXPECT_STREQ(x.child_frame_id, names[b]);
      EXPECT_EQ(x.header.stamp.sec, m.header.stamp.sec);
      EXPECT_EQ(x.header.stamp.nanosec, m.header.stamp.nanosec);
      EXPECT_DOUBLE_EQ(x.transform.translation.x, f.bodies[b].t_world_body_mm[0] * 1e-3);
      EXPECT_DOUBLE_EQ(x.transform.translation.z, 1.5);
      EXPECT_EQ(x.transform.rotation.w, f.bodies[b].q_world_body[0]);
      EXPECT_EQ(x.transform.rotation.z, f.bodies[b].q_world_body[3]);
      EXPECT_EQ(x.transform.rotation.x, 0.0);
    }
  }
  // The fixture's model is not calibrated: no URDF, so no robot_description.
  EXPECT_TRUE(take_all<std_msgs_msg_dds__String_>(reader.desc_, d_loans).empty());
  if (!js_loans.empty())
    dds_return_loan(reader.js_, js_loans.data(), static_cast<int32_t>(js_loans.size()));
  if (!tf_loans.empty())
    dds_return_loan(reader.tf_, tf_loans.data(), static_cast<int32_t>(tf_loans.size()));
}

TEST(Ros2Output, StalledReaderNeverStallsPublish) {
  Fixture fx;
  const std::uint32_t domain = test_domain(1);
  Reader reader(domain);  // matched, but never takes
  ASSERT_TRUE(reader.ok());
  auto sink = make_sink(domain, fx.targets, &fx.model);
  ASSERT_NE(sink, nullptr);
  ASSERT_TRUE(reader.wait_matched());
  auto frame = std::make_unique<FrameResult>();
  constexpr int kFrames = 3000;
  const auto t0 = std::chrono::steady_clock::now();
  for (int s = 1; s <= kFrames; ++s) {
    fill(*frame, static_cast<std::uint64_t>(s));
    sink->publish(*frame);
  }
  const auto dt = std::chrono::steady_clock::now() - t0;
  // A publish() that waited for DDS would take as long as the reader stalls (forever);
  // 3000 copies into the queue take milliseconds, even under sanitizers.
  EXPECT_LT(std::chrono::duration_cast<std::chrono::milliseconds>(dt).count(), 2000);
  for (int i = 0; i < 500; ++i) {
    const OutputCounters c = sink->counters();
    if (c.published + c.dropped + c.failures == kFrames) break;
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  const OutputCounters c = sink->counters();
  EXPECT_EQ(c.published + c.dropped + c.failures, static_cast<std::uint64_t>(kFrames));
  EXPECT_GT(c.dropped, 0u);  // the worker could not keep up with an unpaced burst
  sink.reset();              // stops the worker and deletes the DDS entities promptly
}

// The whole robot (interfaces.md: models of up to 32 bodies, every output carries them
// all): 32 bodies on /tf, the 31 ball joints' 93 DOFs on /joint_states.
TEST(Ros2Output, ThirtyTwoBodiesReachTfAndJointStates) {
  Fixture fx;
  fx.targets.bodies.resize(3);
  fx.model.joints.clear();
  for (int b = 3; b < kMaxResultBodies; ++b) fx.targets.bodies.push_back(fx.targets.bodies[0]);
  for (int b = 0; b < kMaxResultBodies; ++b) {
    fx.targets.bodies[static_cast<std::size_t>(b)].name = "b" + std::to_string(b);
    if (b == 0) continue;
    JointSpec j;
    j.name = "j" + std::to_string(b);
    j.parent = "b" + std::to_string(b - 1);
    j.child = "b" + std::to_string(b);
    j.parent_index = b - 1;
    j.child_index = b;
    fx.model.joints.push_back(j);
  }
  const std::uint32_t domain = test_domain(2);
  Reader reader(domain);
  ASSERT_TRUE(reader.ok());
  auto sink = make_sink(domain, fx.targets, &fx.model);
  ASSERT_NE(sink, nullptr);
  ASSERT_TRUE(reader.wait_matched());
  std::this_thread::sleep_for(std::chrono::milliseconds(200));
  auto f = std::make_unique<FrameResult>();
  f->joints.capture_ns = now_ns(CLOCK_MONOTONIC);
  f->joints.joint_count = kMaxResultBodies - 1;
  for (int j = 0; j < kMaxResultBodies - 1; ++j) f->joints.joints[j].valid = 1;
  f->body_count = kMaxResultBodies;
  for (int b = 0; b < kMaxResultBodies; ++b) f->bodies[static_cast<std::size_t>(b)].found = 1;
  ASSERT_TRUE(sink->publish(*f));
  std::vector<void*> js_loans, tf_loans;
  std::vector<sensor_msgs_msg_dds__JointState_*> js;
  std::vector<tf2_msgs_msg_dds__TFMessage_*> tf;
  for (int i = 0; i < 300 && (js.empty() || tf.empty()); ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
    if (js.empty()) js = take_all<sensor_msgs_msg_dds__JointState_>(reader.js_, js_loans);
    if (tf.empty()) tf = take_all<tf2_msgs_msg_dds__TFMessage_>(reader.tf_, tf_loans);
  }
  ASSERT_EQ(js.size(), 1u);
  ASSERT_EQ(tf.size(), 1u);
  EXPECT_EQ(js[0]->name._length, 3u * (kMaxResultBodies - 1));
  EXPECT_STREQ(js[0]->name._buffer[js[0]->name._length - 1], "j31_z");
  ASSERT_EQ(tf[0]->transforms._length, static_cast<std::uint32_t>(kMaxResultBodies));
  EXPECT_STREQ(tf[0]->transforms._buffer[kMaxResultBodies - 1].child_frame_id, "b31");
  dds_return_loan(reader.js_, js_loans.data(), static_cast<int32_t>(js_loans.size()));
  dds_return_loan(reader.tf_, tf_loans.data(), static_cast<int32_t>(tf_loans.size()));
}

}  // namespace
}  // namespace mocap::publish
