// The ROS 2 additions (interfaces.md, "ROS 2 additions"; docs/ros2.md): the registry's
// "ros2" sink publishes /mocap/<body>/pose (geometry_msgs/PoseStamped) and, when its
// velocities are known, /mocap/<body>/twist (geometry_msgs/TwistStamped) for every body
// found and /mocap/unlabeled_markers (sensor_msgs/PointCloud2) of the points no body
// claimed, and an independent Cyclone DDS reader with ROS 2's names
// (ros2_test_reader.h) checks: each pose equals the body's /tf transform (metres, frame
// "mocap", same stamp), bodies not found send none; the cloud's layout (fields x y z
// FLOAT32 at 0, 4, 8, point_step 12, row_step, height 1, width = unlabelled count, byte
// order flag) and content in metres; the options frame_id (parent of /tf, poses and
// cloud) and world_rotation (a known rotation turns a known pose and point as expected;
// joint angles untouched; the default changes nothing); body names made ROS topic
// tokens; bad option values give one-line errors naming the key. Also the pure mapping
// (ros2_mapping.h: rotations, frame ids, topic tokens, packing).
#include <dds/dds.h>
#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <cstring>
#include <string>
#include <thread>
#include <vector>

#include "core/types.h"
#include "pipeline/publish/output_registry.h"
#include "pipeline/publish/ros2/ros2_mapping.h"
#include "ros2_msgs.h"
#include "tests/publish/ros2_test_reader.h"

namespace mocap::publish {
namespace {

using namespace ros2_test;

// Frame `seq` of the arm: bodies 0 and 1 found (body 2 only on even frames), four points
// of which 1 and 3 are unlabelled, a valid shoulder.
void fill_additions(FrameResult& f, std::uint64_t seq) {
  f = FrameResult{};
  f.joints.sequence = seq;
  f.joints.capture_ns = now_ns(CLOCK_MONOTONIC);
  f.joints.joint_count = 1;
  f.joints.joints[0].valid = 1;
  f.joints.joints[0].type = 1;
  f.joints.joints[0].a[0] = 0.25f;
  f.body_count = 3;
  for (int b = 0; b < 3; ++b) {
    ResultBody& body = f.bodies[static_cast<std::size_t>(b)];
    body.found = (b == 2 && seq % 2 == 1) ? 0 : 1;
    body.t_world_body_mm = {100.0 * b + static_cast<double>(seq), -20.0 * b, 1500.0};
    const double h = 0.1 * static_cast<double>(seq) + 0.3 * b;
    body.q_world_body = {std::cos(h), std::sin(h) * 0.6, 0.0, std::sin(h) * 0.8};
    // Velocities known for the torso from the second frame on (the filter's warm-up).
    body.velocity_valid = b == 0 && seq >= 2 ? 1 : 0;
    body.v_world_mm_s = {100.0f * static_cast<float>(seq), -50.0f, 25.0f};
    body.w_world_rad_s = {0.125f, 0.25f * static_cast<float>(seq), -0.5f};
  }
  f.point_count = 4;
  for (int i = 0; i < 4; ++i) {
    ResultPoint& p = f.points[static_cast<std::size_t>(i)];
    p.X_world_mm = {10.0f * static_cast<float>(i) + static_cast<float>(seq), -250.5f, 1234.25f};
    p.labelled = (i == 1 || i == 3) ? 0 : 1;
  }
}

double metres(float mm) { return static_cast<double>(mm) * 1e-3; }

std::vector<float> cloud_floats(const sensor_msgs_msg_dds__PointCloud2_& c) {
  std::vector<float> v(c.data._length / 4);
  if (!v.empty()) std::memcpy(v.data(), c.data._buffer, v.size() * 4);
  return v;
}

TEST(Ros2Mapping, WorldRotationFrameIdAndTopicTokens) {
  auto id = ros2::parse_world_rotation("identity", "w");
  ASSERT_TRUE(id.ok());
  EXPECT_TRUE(id->identity);
  // camera_to_z_up: x_frame = z_cam, y_frame = -x_cam, z_frame = -y_cam.
  auto cam = ros2::parse_world_rotation("camera_to_z_up", "w");
  ASSERT_TRUE(cam.ok());
  ResultBody body;
  body.t_world_body_mm = {1000.0, 2000.0, 3000.0};  // q = identity
  ros2::PoseOut p = ros2::published_pose(body, *cam);
  EXPECT_NEAR(p.t_m[0], 3.0, 1e-12);
  EXPECT_NEAR(p.t_m[1], -1.0, 1e-12);
  EXPECT_NEAR(p.t_m[2], -2.0, 1e-12);
  EXPECT_NEAR(p.q[0], 0.5, 1e-12);  // REP 103's optical frame: (x y z w) = (-.5 .5 -.5 .5)
  EXPECT_NEAR(p.q[1], -0.5, 1e-12);
  EXPECT_NEAR(p.q[2], 0.5, 1e-12);
  EXPECT_NEAR(p.q[3], -0.5, 1e-12);
  auto yup = ros2::parse_world_rotation("y_up_to_z_up", "w");
  ASSERT_TRUE(yup.ok());
  p = ros2::published_pose(body, *yup);
  EXPECT_NEAR(p.t_m[1], -3.0, 1e-12);
  EXPECT_NEAR(p.t_m[2], 2.0, 1e-12);
  // An explicit quaternion (qw qx qy qz; commas or spaces; 1e-3 off unit is accepted).
  auto z90 = ros2::parse_world_rotation("0.7071, 0, 0 0.7071", "w");
  ASSERT_TRUE(z90.ok()) << z90.error().message;
  p = ros2::published_pose(body, *z90);
  EXPECT_NEAR(p.t_m[0], -2.0, 1e-9);
  EXPECT_NEAR(p.t_m[1], 1.0, 1e-9);
  EXPECT_NEAR(p.q[0], std::sqrt(0.5), 1e-9);
  EXPECT_NEAR(p.q[3], std::sqrt(0.5), 1e-9);
  // Composition: R_frame_world * R_world_body, and qw >= 0 kept.
  body.q_world_body = {0.0, 0.0, 0.0, 1.0};  // 180 degrees about z
  p = ros2::published_pose(body, *z90);      // 270 degrees about z = -90
  EXPECT_NEAR(p.q[0], std::sqrt(0.5), 1e-9);
  EXPECT_NEAR(p.q[3], -std::sqrt(0.5), 1e-9);
  // Velocities turn with the frame: 90 degrees about z takes x to y.
  ResultBody moving;
  moving.v_world_mm_s = {1000.0f, 0.0f, 500.0f};
  moving.w_world_rad_s = {0.0f, 2.0f, 0.0f};
  const ros2::TwistOut v = ros2::published_twist(moving, *z90);
  EXPECT_NEAR(v.v_m_s[0], 0.0, 1e-3);
  EXPECT_NEAR(v.v_m_s[1], 1.0, 1e-3);
  EXPECT_NEAR(v.v_m_s[2], 0.5, 1e-9);
  EXPECT_NEAR(v.w_rad_s[0], -2.0, 1e-3);
  EXPECT_EQ(ros2::published_twist(moving, ros2::WorldRotation{}).v_m_s[2], 0.5);
  // The identity leaves the values exactly as they are.
  p = ros2::published_pose(body, ros2::WorldRotation{});
  EXPECT_EQ(p.t_m[0], 1000.0 * 1e-3);
  EXPECT_EQ(p.q[3], 1.0);
  for (const char* bad : {"enu_please", "1 0 0", "1 0 0 0 0", "2 0 0 0", "0 0 0 0", "1 0 0 x"}) {
    auto e = ros2::parse_world_rotation(bad, "m.yaml: outputs.ros2");
    ASSERT_FALSE(e.ok()) << bad;
    EXPECT_EQ(e.error().message.rfind("m.yaml: outputs.ros2: world_rotation: ", 0), 0u)
        << e.error().message;
    EXPECT_NE(e.error().message.find(std::string("'") + bad + "'"), std::string::npos);
  }
  EXPECT_TRUE(ros2::check_frame_id("odom", "w").ok());
  EXPECT_TRUE(ros2::check_frame_id("robot/world_2", "w").ok());
  for (const char* bad : {"", "/world", "two words", "tab\tbed"})
    EXPECT_FALSE(ros2::check_frame_id(bad, "w").ok()) << bad;
  EXPECT_EQ(ros2::topic_token("left arm"), "left_arm");
  EXPECT_EQ(ros2::topic_token("3rd-finger"), "_3rd_finger");
  EXPECT_EQ(ros2::topic_token("torso"), "torso");
  auto topics = ros2::pose_topics({"torso", "left arm"});
  ASSERT_TRUE(topics.ok());
  EXPECT_EQ((*topics)[1], "rt/mocap/left_arm/pose");
  auto clash = ros2::pose_topics({"left arm", "left_arm"});
  ASSERT_FALSE(clash.ok());
  EXPECT_EQ(clash.error().message.find('\n'), std::string::npos);
  EXPECT_NE(clash.error().message.find("'left arm' and 'left_arm'"), std::string::npos);
}

TEST(Ros2Mapping, PackUnlabelledPointsInMetres) {
  auto f = std::make_unique<FrameResult>();
  fill_additions(*f, 4);
  std::vector<std::uint8_t> data(kMaxResultPoints * ros2::kCloudPointStep);
  ASSERT_EQ(ros2::pack_unlabelled(*f, ros2::WorldRotation{}, data.data()), 2u);
  float xyz[6];
  std::memcpy(xyz, data.data(), sizeof xyz);
  EXPECT_EQ(xyz[0], static_cast<float>(metres(f->points[1].X_world_mm[0])));
  EXPECT_EQ(xyz[3], static_cast<float>(metres(f->points[3].X_world_mm[0])));
  EXPECT_FLOAT_EQ(xyz[5], 1.23425f);
}

TEST(Ros2Output, BadOptionsAreOneLineNamingTheKey) {
  const auto check = [](const char* key, const char* value) {
    return check_outputs({{"ros2", {"true"}, "m.yaml: outputs.ros2", {{key, value}}}});
  };
  auto e = check("world_rotation", "enu");
  ASSERT_FALSE(e.ok());
  EXPECT_EQ(e.error().message,
            "m.yaml: outputs.ros2: world_rotation: expected identity, camera_to_z_up, "
            "y_up_to_z_up or a unit quaternion 'qw qx qy qz', got 'enu'");
  e = check("world_rotation", "0 0 0 2");
  ASSERT_FALSE(e.ok());
  EXPECT_EQ(e.error().message,
            "m.yaml: outputs.ros2: world_rotation: the quaternion's norm is not 1 (within "
            "1e-3), got '0 0 0 2'");
  e = check("frame_id", "my world");
  ASSERT_FALSE(e.ok());
  EXPECT_EQ(e.error().message.rfind("m.yaml: outputs.ros2: frame_id: ", 0), 0u);
  EXPECT_NE(e.error().message.find("'my world'"), std::string::npos);
  e = check("frame", "odom");
  ASSERT_FALSE(e.ok());
  EXPECT_EQ(e.error().message,
            "m.yaml: outputs.ros2: frame: unknown option (known: domain_id frame_id "
            "world_rotation)");
  EXPECT_TRUE(check("world_rotation", "camera_to_z_up").ok());
  EXPECT_TRUE(check("frame_id", "odom").ok());
  // Bodies whose names give the same topic: an error at creation naming both.
  TargetSet targets;
  for (const char* n : {"left arm", "left_arm"}) {
    MarkerTarget t;
    t.name = n;
    targets.bodies.push_back(t);
  }
  OutputContext ctx;
  ctx.targets = &targets;
  auto outs = create_outputs({{"ros2", {"true"}, "--ros2", {{"domain_id", "0"}}}}, ctx);
  ASSERT_FALSE(outs.ok());
  EXPECT_EQ(outs.error().message.rfind("targets.yaml: bodies 'left arm' and 'left_arm': ", 0), 0u)
      << outs.error().message;
}

// Publishes `frames` paced frames of fill_additions and returns when the worker sent them.
void publish_frames(OutputSink& sink, std::vector<FrameResult>& sent) {
  for (std::size_t s = 0; s < sent.size(); ++s) {
    fill_additions(sent[s], s + 1);
    ASSERT_TRUE(sink.publish(sent[s]));
    std::this_thread::sleep_for(std::chrono::milliseconds(3));
  }
  for (int i = 0; i < 300 && sink.counters().published < sent.size(); ++i)
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  EXPECT_EQ(sink.counters().published, sent.size());
  EXPECT_EQ(sink.counters().failures, 0u);
  std::this_thread::sleep_for(std::chrono::milliseconds(200));
}

TEST(Ros2Output, PosesEqualTfAndTheCloudHoldsTheUnlabelledPoints) {
  ArmFixture fx;
  fx.targets.bodies[1].name = "upper arm";  // published as /mocap/upper_arm/pose
  const std::uint32_t domain = test_domain(3);
  Reader reader(domain, {"torso", "upper_arm", "forearm"});
  ASSERT_TRUE(reader.ok());
  auto sink = make_sink(domain, fx.targets, &fx.model);
  ASSERT_NE(sink, nullptr);
  ASSERT_TRUE(reader.wait_matched());
  std::this_thread::sleep_for(std::chrono::milliseconds(200));
  std::vector<FrameResult> sent(6);
  publish_frames(*sink, sent);

  std::vector<void*> tf_loans, cloud_loans;
  const auto tf = take_all<tf2_msgs_msg_dds__TFMessage_>(reader.tf_, tf_loans);
  const auto clouds = take_all<sensor_msgs_msg_dds__PointCloud2_>(reader.cloud_, cloud_loans);
  ASSERT_EQ(tf.size(), sent.size());
  ASSERT_EQ(clouds.size(), sent.size());  // one cloud per frame
  std::vector<std::vector<void*>> pose_loans(3);
  std::vector<std::vector<geometry_msgs_msg_dds__PoseStamped_*>> poses(3);
  for (std::size_t b = 0; b < 3; ++b)
    poses[b] = take_all<geometry_msgs_msg_dds__PoseStamped_>(reader.poses_[b], pose_loans[b]);
  EXPECT_EQ(poses[0].size(), sent.size());
  EXPECT_EQ(poses[1].size(), sent.size());
  EXPECT_EQ(poses[2].size(), sent.size() / 2);  // found on even frames only
  std::size_t next[3] = {0, 0, 0};
  for (std::size_t s = 0; s < sent.size(); ++s) {
    const tf2_msgs_msg_dds__TFMessage_& t = *tf[s];
    for (std::uint32_t k = 0; k < t.transforms._length; ++k) {
      const auto& x = t.transforms._buffer[k];
      const std::size_t b = std::string(x.child_frame_id) == "torso"       ? 0
                            : std::string(x.child_frame_id) == "upper arm" ? 1
                                                                           : 2;
      ASSERT_LT(next[b], poses[b].size());
      const geometry_msgs_msg_dds__PoseStamped_& p = *poses[b][next[b]++];
      EXPECT_STREQ(p.header.frame_id, "mocap");
      EXPECT_EQ(p.header.stamp.sec, x.header.stamp.sec);
      EXPECT_EQ(p.header.stamp.nanosec, x.header.stamp.nanosec);
      EXPECT_EQ(p.pose.position.x, x.transform.translation.x);  // the same pose, metres
      EXPECT_EQ(p.pose.position.y, x.transform.translation.y);
      EXPECT_EQ(p.pose.position.z, 1.5);
      EXPECT_EQ(p.pose.orientation.w, x.transform.rotation.w);
      EXPECT_EQ(p.pose.orientation.x, x.transform.rotation.x);
      EXPECT_EQ(p.pose.orientation.z, sent[s].bodies[b].q_world_body[3]);
    }
    const sensor_msgs_msg_dds__PointCloud2_& c = *clouds[s];
    EXPECT_STREQ(c.header.frame_id, "mocap");
    EXPECT_EQ(c.header.stamp.sec, t.transforms._buffer[0].header.stamp.sec);
    EXPECT_EQ(c.header.stamp.nanosec, t.transforms._buffer[0].header.stamp.nanosec);
    EXPECT_EQ(c.height, 1u);
    ASSERT_EQ(c.width, 2u);  // points 1 and 3: no body claimed them
    ASSERT_EQ(c.fields._length, 3u);
    for (std::uint32_t k = 0; k < 3; ++k) {
      EXPECT_EQ(std::string(c.fields._buffer[k].name), std::string(1, "xyz"[k]));
      EXPECT_EQ(c.fields._buffer[k].offset, 4 * k);
      EXPECT_EQ(c.fields._buffer[k].datatype, 7);  // FLOAT32
      EXPECT_EQ(c.fields._buffer[k].count, 1u);
    }
    EXPECT_EQ(c.is_bigendian, std::endian::native == std::endian::big);
    EXPECT_EQ(c.point_step, 12u);
    EXPECT_EQ(c.row_step, 24u);
    ASSERT_EQ(c.data._length, 24u);
    EXPECT_TRUE(c.is_dense);
    const std::vector<float> v = cloud_floats(c);
    for (int i = 0; i < 2; ++i)
      for (int k = 0; k < 3; ++k)
        EXPECT_NEAR(v[static_cast<std::size_t>(3 * i + k)],
                    metres(sent[s].points[static_cast<std::size_t>(1 + 2 * i)].X_world_mm[k]),
                    1e-6);
  }
  dds_return_loan(reader.tf_, tf_loans.data(), static_cast<int32_t>(tf_loans.size()));
  dds_return_loan(reader.cloud_, cloud_loans.data(), static_cast<int32_t>(cloud_loans.size()));
  for (std::size_t b = 0; b < 3; ++b)
    if (!pose_loans[b].empty())
      dds_return_loan(reader.poses_[b], pose_loans[b].data(),
                      static_cast<int32_t>(pose_loans[b].size()));
  // /mocap/<body>/twist: the torso's velocities from its second frame, in m/s and rad/s,
  // stamped as its pose; nothing for bodies whose velocities are not known.
  std::vector<void*> tw_loans;
  const auto twists =
      take_all<geometry_msgs_msg_dds__TwistStamped_>(reader.twists_[0], tw_loans);
  ASSERT_EQ(twists.size(), sent.size() - 1);
  for (std::size_t k = 0; k < twists.size(); ++k) {
    const FrameResult& f = sent[k + 1];
    EXPECT_STREQ(twists[k]->header.frame_id, "mocap");
    EXPECT_DOUBLE_EQ(twists[k]->twist.linear.x, metres(f.bodies[0].v_world_mm_s[0]));
    EXPECT_DOUBLE_EQ(twists[k]->twist.linear.y, -0.05);
    EXPECT_DOUBLE_EQ(twists[k]->twist.angular.y,
                     static_cast<double>(f.bodies[0].w_world_rad_s[1]));
    EXPECT_DOUBLE_EQ(twists[k]->twist.angular.z, -0.5);
  }
  if (!tw_loans.empty())
    dds_return_loan(reader.twists_[0], tw_loans.data(), static_cast<int32_t>(tw_loans.size()));
  std::vector<void*> none_loans;
  EXPECT_TRUE(
      take_all<geometry_msgs_msg_dds__TwistStamped_>(reader.twists_[1], none_loans).empty());
}

TEST(Ros2Output, FrameIdAndWorldRotationTurnTfPosesAndCloudNotJoints) {
  ArmFixture fx;
  const std::uint32_t domain = test_domain(4);
  Reader reader(domain, {"torso"});
  ASSERT_TRUE(reader.ok());
  auto sink = make_sink(domain, fx.targets, &fx.model,
                        {{"frame_id", "robot_world"}, {"world_rotation", "camera_to_z_up"}});
  ASSERT_NE(sink, nullptr);
  ASSERT_TRUE(reader.wait_matched());
  std::this_thread::sleep_for(std::chrono::milliseconds(200));
  std::vector<FrameResult> sent(2);
  publish_frames(*sink, sent);
  std::vector<void*> tf_loans, cloud_loans, pose_loans, js_loans;
  const auto tf = take_all<tf2_msgs_msg_dds__TFMessage_>(reader.tf_, tf_loans);
  const auto clouds = take_all<sensor_msgs_msg_dds__PointCloud2_>(reader.cloud_, cloud_loans);
  const auto poses = take_all<geometry_msgs_msg_dds__PoseStamped_>(reader.poses_[0], pose_loans);
  const auto js = take_all<sensor_msgs_msg_dds__JointState_>(reader.js_, js_loans);
  ASSERT_EQ(tf.size(), 2u);
  ASSERT_EQ(clouds.size(), 2u);
  ASSERT_EQ(poses.size(), 2u);
  ASSERT_EQ(js.size(), 2u);
  for (std::size_t s = 0; s < 2; ++s) {
    const ResultBody& b = sent[s].bodies[0];
    const auto& x = tf[s]->transforms._buffer[0];
    EXPECT_STREQ(x.header.frame_id, "robot_world");
    EXPECT_STREQ(x.child_frame_id, "torso");
    // camera_to_z_up: (x, y, z) -> (z, -x, -y); q -> q_R * q with q_R = (.5, -.5, .5, -.5).
    EXPECT_NEAR(x.transform.translation.x, b.t_world_body_mm[2] * 1e-3, 1e-12);
    EXPECT_NEAR(x.transform.translation.y, -b.t_world_body_mm[0] * 1e-3, 1e-12);
    EXPECT_NEAR(x.transform.translation.z, -b.t_world_body_mm[1] * 1e-3, 1e-12);
    const Quat q = Quat(0.5, -0.5, 0.5, -0.5) *
                   Quat(b.q_world_body[0], b.q_world_body[1], b.q_world_body[2], b.q_world_body[3]);
    const double sign = q.w() < 0 ? -1.0 : 1.0;
    EXPECT_NEAR(x.transform.rotation.w, sign * q.w(), 1e-12);
    EXPECT_NEAR(x.transform.rotation.x, sign * q.x(), 1e-12);
    EXPECT_NEAR(x.transform.rotation.y, sign * q.y(), 1e-12);
    EXPECT_NEAR(x.transform.rotation.z, sign * q.z(), 1e-12);
    const auto& p = *poses[s];
    EXPECT_STREQ(p.header.frame_id, "robot_world");
    EXPECT_EQ(p.pose.position.x, x.transform.translation.x);
    EXPECT_EQ(p.pose.position.y, x.transform.translation.y);
    EXPECT_EQ(p.pose.orientation.w, x.transform.rotation.w);
    EXPECT_EQ(p.pose.orientation.y, x.transform.rotation.y);
    EXPECT_STREQ(clouds[s]->header.frame_id, "robot_world");
    const std::vector<float> v = cloud_floats(*clouds[s]);
    ASSERT_EQ(v.size(), 6u);
    const auto& X = sent[s].points[1].X_world_mm;
    EXPECT_NEAR(v[0], metres(X[2]), 1e-6);
    EXPECT_NEAR(v[1], -metres(X[0]), 1e-6);
    EXPECT_NEAR(v[2], -metres(X[1]), 1e-6);
    ASSERT_EQ(js[s]->position._length, 3u);  // joint angles are relative: not turned
    EXPECT_EQ(js[s]->position._buffer[0], 0.25);
  }
  dds_return_loan(reader.tf_, tf_loans.data(), static_cast<int32_t>(tf_loans.size()));
  dds_return_loan(reader.cloud_, cloud_loans.data(), static_cast<int32_t>(cloud_loans.size()));
  dds_return_loan(reader.poses_[0], pose_loans.data(), static_cast<int32_t>(pose_loans.size()));
  dds_return_loan(reader.js_, js_loans.data(), static_cast<int32_t>(js_loans.size()));
}

}  // namespace
}  // namespace mocap::publish
