// The ROS 2 output of the whole-body humanoid end to end (interfaces.md, "ROS 2": every
// joint DOF on /joint_states named as in the URDF of `mocap calibrate --urdf`, every body
// found on /tf): the registry's "ros2" sink with the humanoid's targets and true model
// publishes one full frame (tests/pipeline/humanoid_frame.h: 15 bodies, 14 joints) into a
// DDS domain of its own, and a Cyclone DDS reader with ROS 2's names and types receives
// the URDF on rt/robot_description (transient local) and the frame. Checked against
// that URDF: the /joint_states names are exactly its 30 revolute joints (8 balls x 3 + 6
// hinges), listed in model order (hinge J; ball J_x, J_y, J_z) with the tracker's angles, and
// the /tf child frames are exactly its 15 body links, posed in metres. (The 32-body
// capacity with synthetic names: test_ros2.cpp, Ros2Output.ThirtyTwoBodiesReachTfAndJointStates.)
// The 2027-01 additions at this scale: /mocap/<body>/pose of all 15 bodies equals their
// /tf transforms, and /mocap/unlabeled_markers holds exactly the frame's two strays.
#include <dds/dds.h>
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <cstring>
#include <set>
#include <string>
#include <thread>
#include <vector>

#include "pipeline/publish/output_registry.h"
#include "pipeline/publish/ros2/ros2_mapping.h"
#include "ros2_msgs.h"
#include "tests/pipeline/humanoid_frame.h"
#include "tests/publish/ros2_test_reader.h"

namespace mocap::publish {
namespace {

using namespace ros2_test;  // Reader, take_one, test_domain

TEST(Ros2Humanoid, JointStatesAndTfAreNamedAsTheUrdf) {
  auto h = testing::make_humanoid_frame(3, 21);
  const sim::SimScene& sc = h->scene;
  ASSERT_EQ(sc.body_count(), 15);
  const std::uint32_t domain = test_domain(7);
  std::vector<std::string> tokens;  // /mocap/<body>/pose of every body
  for (const MarkerTarget& b : sc.targets.bodies) tokens.push_back(ros2::topic_token(b.name));
  Reader reader(domain, tokens);
  ASSERT_TRUE(reader.ok());
  OutputContext ctx;
  ctx.targets = &sc.targets;
  ctx.model = &sc.joints_true;
  auto outs = create_outputs(
      {{"ros2", {"true"}, "test: outputs.ros2", {{"domain_id", std::to_string(domain)}}}}, ctx);
  ASSERT_TRUE(outs.ok()) << outs.error().message;
  ASSERT_EQ(outs->sinks.size(), 1u) << (outs->notices.empty() ? "" : outs->notices[0]);
  OutputSink& sink = *outs->sinks[0];
  ASSERT_TRUE(reader.wait_matched(true));
  std::this_thread::sleep_for(std::chrono::milliseconds(200));  // the writers match too

  // The URDF as ROS nodes get it: its revolute joints and its links.
  void* desc_loan = nullptr;
  auto* desc = take_one<std_msgs_msg_dds__String_>(reader.desc_, desc_loan);
  ASSERT_NE(desc, nullptr) << "no robot_description";
  const std::string urdf = desc->data;
  dds_return_loan(reader.desc_, &desc_loan, 1);
  // The names between `prefix` and `suffix`, in order (a plain scan: std::regex trips
  // GCC 12's -Wmaybe-uninitialized under the sanitizers).
  const auto names_between = [&urdf](const std::string& prefix, const std::string& suffix) {
    std::vector<std::string> names;
    for (std::size_t at = urdf.find(prefix); at != std::string::npos;
         at = urdf.find(prefix, at + 1)) {
      const std::size_t begin = at + prefix.size();
      const std::size_t end = urdf.find('"', begin);
      if (end == std::string::npos) break;
      if (urdf.compare(end, suffix.size(), suffix) == 0)
        names.push_back(urdf.substr(begin, end - begin));
    }
    return names;
  };
  const std::vector<std::string> revolute =
      names_between("<joint name=\"", "\" type=\"revolute\">");
  const std::vector<std::string> link_list = names_between("<link name=\"", "\"/>");
  const std::set<std::string> links(link_list.begin(), link_list.end());
  ASSERT_EQ(revolute.size(), 30u);
  ASSERT_EQ(links.size(), 45u);

  const auto frame = h->make_result(1'000'000'000);
  ASSERT_TRUE(sink.publish(*frame));
  void* js_loan = nullptr;
  void* tf_loan = nullptr;
  auto* js = take_one<sensor_msgs_msg_dds__JointState_>(reader.js_, js_loan);
  auto* tf = take_one<tf2_msgs_msg_dds__TFMessage_>(reader.tf_, tf_loan);
  ASSERT_NE(js, nullptr);
  ASSERT_NE(tf, nullptr);
  ASSERT_EQ(js->name._length, 30u);
  ASSERT_EQ(js->position._length, 30u);
  // Model order (the datagram's), each DOF by its URDF name: a hinge J, a ball J_x/_y/_z.
  std::size_t i = 0;
  for (std::size_t j = 0; j < sc.joints_true.joints.size(); ++j) {
    const JointSpec& s = sc.joints_true.joints[j];
    const kinematics::JointAngle& a = h->out->angles.joints[j];
    const double angle[3] = {a.a0, a.a1, a.a2};
    const bool hinge = s.type == JointType::kHinge;
    for (int d = 0; d < (hinge ? 1 : 3); ++d, ++i) {
      const std::string expected = hinge ? s.name : s.name + "_" + "xyz"[d];
      EXPECT_EQ(js->name._buffer[i], expected) << "entry " << i;
      EXPECT_NEAR(js->position._buffer[i], angle[d], 1e-6) << js->name._buffer[i];
    }
  }
  // ... and the names are exactly the URDF's revolute joints.
  std::set<std::string> names;
  for (std::uint32_t k = 0; k < js->name._length; ++k) names.insert(js->name._buffer[k]);
  EXPECT_EQ(names, std::set<std::string>(revolute.begin(), revolute.end()));
  ASSERT_EQ(tf->transforms._length, 15u);
  std::set<std::string> children;
  for (std::uint32_t b = 0; b < tf->transforms._length; ++b) {
    const auto& t = tf->transforms._buffer[b];
    EXPECT_STREQ(t.header.frame_id, "mocap");
    EXPECT_TRUE(links.count(t.child_frame_id)) << t.child_frame_id << " is no URDF link";
    children.insert(t.child_frame_id);
    const Vec3 tr = h->T_world_body[b].translation() * 1e-3;
    EXPECT_NEAR(t.transform.translation.x, tr.x(), 1e-9);
    EXPECT_NEAR(t.transform.translation.z, tr.z(), 1e-9);
    const Quat q(h->T_world_body[b].linear());
    EXPECT_NEAR(std::abs(t.transform.rotation.w * q.w() + t.transform.rotation.x * q.x() +
                         t.transform.rotation.y * q.y() + t.transform.rotation.z * q.z()),
                1.0, 1e-9);
  }
  for (const MarkerTarget& b : sc.targets.bodies) EXPECT_TRUE(children.count(b.name)) << b.name;
  // /mocap/<body>/pose of every body (all found): the /tf pose, frame "mocap", metres.
  for (std::size_t b = 0; b < tokens.size(); ++b) {
    void* loan = nullptr;
    auto* p = take_one<geometry_msgs_msg_dds__PoseStamped_>(reader.poses_[b], loan);
    ASSERT_NE(p, nullptr) << "no /mocap/" << tokens[b] << "/pose";
    const auto& t = tf->transforms._buffer[b];
    EXPECT_STREQ(t.child_frame_id, sc.targets.bodies[b].name.c_str());
    EXPECT_STREQ(p->header.frame_id, "mocap");
    EXPECT_EQ(p->header.stamp.sec, t.header.stamp.sec);
    EXPECT_EQ(p->header.stamp.nanosec, t.header.stamp.nanosec);
    EXPECT_EQ(p->pose.position.x, t.transform.translation.x) << tokens[b];
    EXPECT_EQ(p->pose.position.y, t.transform.translation.y);
    EXPECT_EQ(p->pose.position.z, t.transform.translation.z);
    EXPECT_EQ(p->pose.orientation.w, t.transform.rotation.w);
    EXPECT_EQ(p->pose.orientation.x, t.transform.rotation.x);
    EXPECT_EQ(p->pose.orientation.y, t.transform.rotation.y);
    EXPECT_EQ(p->pose.orientation.z, t.transform.rotation.z);
    dds_return_loan(reader.poses_[b], &loan, 1);
  }
  // /mocap/unlabeled_markers: of the 71 markers and 2 strays only the strays (the
  // pipeline's make_frame_result decided which points the bodies claimed), in metres.
  void* cloud_loan = nullptr;
  auto* cloud = take_one<sensor_msgs_msg_dds__PointCloud2_>(reader.cloud_, cloud_loan);
  ASSERT_NE(cloud, nullptr);
  ASSERT_EQ(frame->point_count, 73);
  ASSERT_EQ(cloud->width, 2u);
  ASSERT_EQ(cloud->data._length, 24u);
  float xyz[6];
  std::memcpy(xyz, cloud->data._buffer, sizeof xyz);
  const double strays[6] = {-0.7, 0.3, 0.4, 0.65, -0.2, 1.7};
  for (int k = 0; k < 6; ++k) EXPECT_NEAR(xyz[k], strays[k], 1e-6) << k;
  dds_return_loan(reader.cloud_, &cloud_loan, 1);
  dds_return_loan(reader.js_, &js_loan, 1);
  dds_return_loan(reader.tf_, &tf_loan, 1);
}

}  // namespace
}  // namespace mocap::publish
