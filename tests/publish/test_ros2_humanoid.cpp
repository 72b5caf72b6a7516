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
#include <dds/dds.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <set>
#include <string>
#include <thread>
#include <vector>

#include "pipeline/publish/output_registry.h"
#include "ros2_msgs.h"
#include "tests/pipeline/humanoid_frame.h"

namespace mocap::publish {
namespace {

std::uint32_t test_domain() { return static_cast<std::uint32_t>(100 + (::getpid() * 3 + 7) % 120); }

class Reader {
 public:
  explicit Reader(std::uint32_t domain) {
    participant_ = dds_create_participant(domain, nullptr, nullptr);
    dds_qos_t* qos = dds_create_qos();
    dds_qset_reliability(qos, DDS_RELIABILITY_RELIABLE, DDS_SECS(1));
    dds_qset_history(qos, DDS_HISTORY_KEEP_ALL, 0);
    js_ = reader(qos, &sensor_msgs_msg_dds__JointState__desc, "rt/joint_states");
    tf_ = reader(qos, &tf2_msgs_msg_dds__TFMessage__desc, "rt/tf");
    dds_qset_durability(qos, DDS_DURABILITY_TRANSIENT_LOCAL);
    desc_ = reader(qos, &std_msgs_msg_dds__String__desc, "rt/robot_description");
    dds_delete_qos(qos);
  }
  ~Reader() {
    if (participant_ > 0) dds_delete(participant_);
  }
  bool ok() const { return participant_ > 0 && js_ > 0 && tf_ > 0 && desc_ > 0; }
  bool wait_matched() {
    for (int i = 0; i < 500; ++i) {
      dds_subscription_matched_status_t a{}, b{}, c{};
      dds_get_subscription_matched_status(js_, &a);
      dds_get_subscription_matched_status(tf_, &b);
      dds_get_subscription_matched_status(desc_, &c);
      if (a.current_count > 0 && b.current_count > 0 && c.current_count > 0) return true;
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
    return false;
  }
  // One sample of `reader` (waits up to 3 s); the loan is returned by the caller.
  template <class T>
  T* take_one(dds_entity_t reader, void*& loan) {
    for (int i = 0; i < 300; ++i) {
      void* samples[1] = {nullptr};
      dds_sample_info_t info[1];
      if (dds_take(reader, samples, info, 1, 1) == 1) {
        loan = samples[0];
        if (info[0].valid_data) return static_cast<T*>(samples[0]);
        dds_return_loan(reader, samples, 1);
        continue;
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
    return nullptr;
  }
  dds_entity_t js_ = 0, tf_ = 0, desc_ = 0;

 private:
  dds_entity_t reader(const dds_qos_t* qos, const dds_topic_descriptor_t* d, const char* name) {
    const dds_entity_t t = dds_create_topic(participant_, d, name, nullptr, nullptr);
    return t < 0 ? t : dds_create_reader(participant_, t, qos, nullptr);
  }
  dds_entity_t participant_ = 0;
};

TEST(Ros2Humanoid, JointStatesAndTfAreNamedAsTheUrdf) {
  auto h = testing::make_humanoid_frame(3, 21);
  const sim::SimScene& sc = h->scene;
  ASSERT_EQ(sc.body_count(), 15);
  const std::uint32_t domain = test_domain();
  Reader reader(domain);
  ASSERT_TRUE(reader.ok());
  OutputContext ctx;
  ctx.targets = &sc.targets;
  ctx.model = &sc.joints_true;
  auto outs = create_outputs(
      {{"ros2", {"true"}, "test: outputs.ros2", {{"domain_id", std::to_string(domain)}}}}, ctx);
  ASSERT_TRUE(outs.ok()) << outs.error().message;
  ASSERT_EQ(outs->sinks.size(), 1u) << (outs->notices.empty() ? "" : outs->notices[0]);
  OutputSink& sink = *outs->sinks[0];
  ASSERT_TRUE(reader.wait_matched());
  std::this_thread::sleep_for(std::chrono::milliseconds(200));  // the writers match too

  // The URDF as ROS nodes get it: its revolute joints and its links.
  void* desc_loan = nullptr;
  auto* desc = reader.take_one<std_msgs_msg_dds__String_>(reader.desc_, desc_loan);
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
  auto* js = reader.take_one<sensor_msgs_msg_dds__JointState_>(reader.js_, js_loan);
  auto* tf = reader.take_one<tf2_msgs_msg_dds__TFMessage_>(reader.tf_, tf_loan);
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
  dds_return_loan(reader.js_, &js_loan, 1);
  dds_return_loan(reader.tf_, &tf_loan, 1);
}

}  // namespace
}  // namespace mocap::publish
