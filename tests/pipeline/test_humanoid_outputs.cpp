// Every output at scale on the whole-body humanoid (interfaces.md, "The whole robot"): a
// full frame of its 15 bodies, 71 markers and 14 joints of the true model (8 ball, 6
// hinge; humanoid_frame.h, no rendering) goes through make_frame_result like the identify
// stage's, then into each output's encoder: the UDP datagram (14 joint records in model
// order, the tracker's angles), the iceoryx payload (the same JointsMessage, decoded
// field for field from the datagram), and, when built, the Foxglove live view's scene
// (15 bodies with colours, 14 calibrated joints, every rig camera a blob channel: with
// the humanoid's 8 cameras that is 11 channels, and the server must accept them), /tf
// (every body's pose in metres), /markers (71 labelled markers coloured by body, every
// point, 15 labels, 14 joint centres where the parent puts them and 6 hinge axes) and
// /joints (names, types and angles of the model). ROS 2: tests/publish/test_ros2_humanoid.cpp.
#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <string>
#include <vector>

#include "client/datagram.h"
#include "tests/pipeline/humanoid_frame.h"
#ifdef MOCAP_HAVE_FOXGLOVE
#include <nlohmann/json.hpp>

#include "pipeline/foxglove/blob_overlay.h"
#include "pipeline/foxglove/encode.h"
#include "pipeline/foxglove/server.h"
#endif

namespace mocap::pipeline {
namespace {

using testing::make_humanoid_frame;

constexpr int kBodies = 15, kJoints = 14, kMarkers = 71;

TEST(HumanoidOutputs, FullFrameFillsTheFrameResult) {
  auto h = make_humanoid_frame(3, 11);
  ASSERT_EQ(h->scene.body_count(), kBodies);
  ASSERT_EQ(h->scene.marker_count(), kMarkers);
  const auto r = h->make_result(123456789);
  EXPECT_EQ(r->body_count, kBodies);
  EXPECT_EQ(r->marker_count, kMarkers);
  EXPECT_EQ(r->point_count, kMarkers + h->stray_points);
  EXPECT_EQ(r->joints.joint_count, kJoints);
  EXPECT_EQ(r->joints.flags & client::kFlagAllBodiesFound, client::kFlagAllBodiesFound);
  EXPECT_EQ(r->camera_count, 3);
  for (int b = 0; b < kBodies; ++b) {
    const publish::ResultBody& rb = r->bodies[static_cast<std::size_t>(b)];
    EXPECT_EQ(rb.found, 1) << b;
    const Vec3 t = h->T_world_body[static_cast<std::size_t>(b)].translation();
    EXPECT_NEAR(rb.t_world_body_mm[0], t.x(), 1e-9);
    EXPECT_NEAR(rb.t_world_body_mm[2], t.z(), 1e-9);
  }
  // Labelled markers in body and marker order, at the posed model marker.
  int k = 0;
  for (int b = 0; b < kBodies; ++b) {
    const auto& markers = h->scene.targets.bodies[static_cast<std::size_t>(b)].markers_body;
    for (std::size_t m = 0; m < markers.size(); ++m, ++k) {
      const publish::ResultMarker& rm = r->markers[static_cast<std::size_t>(k)];
      EXPECT_EQ(rm.body, b);
      EXPECT_EQ(rm.marker, m);
      const Vec3 X = h->T_world_body[static_cast<std::size_t>(b)] * markers[m];
      EXPECT_NEAR(rm.X_world_mm[1], X.y(), 1e-3);
      EXPECT_LT(rm.residual_mm, 1e-3f);
    }
  }
  int marker_blobs = 0;
  for (int c = 0; c < r->camera_count; ++c) {
    const publish::CameraBlobs& cb = r->cameras[static_cast<std::size_t>(c)];
    EXPECT_EQ(cb.count, h->out->blobs[static_cast<std::size_t>(c)].size());
    for (int i = 0; i < cb.count; ++i)
      marker_blobs += r->blobs_of(c)[i].use == static_cast<std::uint8_t>(publish::BlobUse::kMarker);
  }
  EXPECT_GT(marker_blobs, kMarkers);  // most markers are in more than one view
}

TEST(HumanoidOutputs, FourteenJointRecordsInTheDatagramAndTheIceoryxPayload) {
  auto h = make_humanoid_frame(3, 12);
  const auto r = h->make_result(987654321);
  const JointModel& model = h->scene.joints_true;
  // iceoryx publishes r->joints, the public JointsMessage, as its chunk (iceoryx_sink.cpp);
  // UDP encodes the same message.
  const client::JointsMessage& msg = r->joints;
  std::vector<std::uint8_t> buf(client::kMaxDatagramBytes);
  const std::size_t n = client::encode_datagram(msg, buf.data(), buf.size());
  ASSERT_EQ(n, client::datagram_size(kJoints));
  EXPECT_EQ(n, 40u + 32u * kJoints + 4u);
  client::JointsMessage back;
  ASSERT_EQ(client::decode_datagram(buf.data(), n, back), client::DecodeStatus::kOk);
  EXPECT_EQ(back.sequence, 7u);
  EXPECT_EQ(back.capture_ns, 987654321);
  EXPECT_EQ(back.flags & client::kFlagAllBodiesFound, client::kFlagAllBodiesFound);
  ASSERT_EQ(back.joint_count, kJoints);
  int hinges = 0;
  for (int j = 0; j < kJoints; ++j) {
    const JointSpec& s = model.joints[static_cast<std::size_t>(j)];
    const kinematics::JointAngle& a = h->out->angles.joints[static_cast<std::size_t>(j)];
    const client::JointRecord& rec = back.joints[j];
    const bool hinge = s.type == JointType::kHinge;
    hinges += hinge;
    EXPECT_EQ(rec.index, j);
    EXPECT_EQ(rec.type, hinge ? 1 : 0) << s.name;
    EXPECT_EQ(rec.valid, 1) << s.name;
    EXPECT_FLOAT_EQ(rec.a[0], static_cast<float>(a.a0)) << s.name;
    EXPECT_FLOAT_EQ(rec.a[1], static_cast<float>(a.a1)) << s.name;
    EXPECT_FLOAT_EQ(rec.a[2], static_cast<float>(a.a2)) << s.name;
    EXPECT_FLOAT_EQ(rec.q[0], static_cast<float>(a.q_parent_child.w())) << s.name;
    EXPECT_FLOAT_EQ(rec.q[3], static_cast<float>(a.q_parent_child.z())) << s.name;
    if (hinge) {
      EXPECT_EQ(rec.a[1], 0.0f);
    }
    // The payload iceoryx carries is the message itself: field for field the datagram's.
    EXPECT_EQ(msg.joints[j].index, rec.index);
    EXPECT_EQ(msg.joints[j].type, rec.type);
    for (int c = 0; c < 3; ++c) EXPECT_EQ(msg.joints[j].a[c], rec.a[c]);
    for (int c = 0; c < 4; ++c) EXPECT_EQ(msg.joints[j].q[c], rec.q[c]);
  }
  EXPECT_EQ(hinges, 6);
}

#ifdef MOCAP_HAVE_FOXGLOVE
Vec3 json_vec(const nlohmann::json& v) {
  return Vec3(v["x"].get<double>(), v["y"].get<double>(), v["z"].get<double>());
}

TEST(HumanoidOutputs, FoxgloveSceneOfAllBodiesJointsAndCameras) {
  auto h = make_humanoid_frame(8, 13);  // the humanoid's default ring of 8 cameras
  const sim::SimScene& sc = h->scene;
  auto scene = foxglove::make_scene(sc.targets, &sc.joints_true, &sc.rig);
  ASSERT_TRUE(scene.ok()) << scene.error().message;
  ASSERT_EQ(scene->bodies.size(), static_cast<std::size_t>(kBodies));
  ASSERT_EQ(scene->joints.size(), static_cast<std::size_t>(kJoints));
  for (const foxglove::SceneJoint& j : scene->joints) EXPECT_TRUE(j.calibrated) << j.name;
  ASSERT_EQ(scene->cameras.size(), 8u);
  const auto channels = foxglove::live_view_channels(*scene);
  EXPECT_EQ(channels.size(), 4u + 8u);  // /tf /markers /joints /bodies + 8 cameras
  // The server takes every channel (a rig of 6..8 cameras used to be refused here).
  foxglove::ServerOptions o;
  o.port = 0;
  auto server = foxglove::Server::create(o, channels);
  ASSERT_TRUE(server.ok()) << server.error().message;
  const auto r = h->make_result(1000);
  for (int c = 0; c < 8; ++c) {
    const auto overlay = nlohmann::json::parse(foxglove::encode_blob_overlay(*scene, *r, c, 5));
    EXPECT_EQ(overlay["frame_id"], sc.rig.cameras[static_cast<std::size_t>(c)].name);
  }
}

TEST(HumanoidOutputs, FoxgloveTransformsMarkersJointsAndAngles) {
  auto h = make_humanoid_frame(3, 14);
  const sim::SimScene& sc = h->scene;
  auto scene = foxglove::make_scene(sc.targets, &sc.joints_true, &sc.rig);
  ASSERT_TRUE(scene.ok()) << scene.error().message;
  const auto r = h->make_result(1000);
  const auto tf = nlohmann::json::parse(foxglove::encode_frame_transforms(*scene, *r, 42));
  ASSERT_EQ(tf["transforms"].size(), static_cast<std::size_t>(kBodies));
  for (int b = 0; b < kBodies; ++b) {
    const auto& t = tf["transforms"][static_cast<std::size_t>(b)];
    const Iso3& T = h->T_world_body[static_cast<std::size_t>(b)];
    EXPECT_EQ(t["parent_frame_id"], "mocap");
    EXPECT_EQ(t["child_frame_id"], sc.targets.bodies[static_cast<std::size_t>(b)].name);
    EXPECT_LT((json_vec(t["translation"]) - T.translation() * 1e-3).norm(), 1e-9);
    const Quat q(t["rotation"]["w"].get<double>(), t["rotation"]["x"].get<double>(),
                 t["rotation"]["y"].get<double>(), t["rotation"]["z"].get<double>());
    EXPECT_LT((q.toRotationMatrix() - T.linear()).norm(), 1e-9);
  }
  const auto su = nlohmann::json::parse(foxglove::encode_scene_update(*scene, *r, 42));
  nlohmann::json markers, points, labels, joints;
  for (const auto& e : su["entities"]) {
    if (e["id"] == "markers") markers = e;
    if (e["id"] == "points") points = e;
    if (e["id"] == "bodies") labels = e;
    if (e["id"] == "joints") joints = e;
  }
  ASSERT_EQ(markers["spheres"].size(), static_cast<std::size_t>(kMarkers));
  EXPECT_EQ(points["spheres"].size(), static_cast<std::size_t>(kMarkers + h->stray_points));
  ASSERT_EQ(labels["texts"].size(), static_cast<std::size_t>(kBodies));
  for (int b = 0; b < kBodies; ++b)
    EXPECT_EQ(labels["texts"][static_cast<std::size_t>(b)]["text"],
              sc.targets.bodies[static_cast<std::size_t>(b)].name);
  // Marker k of body b is coloured like body b.
  for (int k = 0; k < kMarkers; ++k) {
    const int body = r->markers[static_cast<std::size_t>(k)].body;
    EXPECT_DOUBLE_EQ(markers["spheres"][static_cast<std::size_t>(k)]["color"]["r"].get<double>(),
                     scene->bodies[static_cast<std::size_t>(body)].colour.r);
  }
  // A joint centre where the parent puts it is where the child puts it (true model).
  ASSERT_EQ(joints["spheres"].size(), static_cast<std::size_t>(kJoints));
  EXPECT_EQ(joints["arrows"].size(), 6u);
  for (int j = 0; j < kJoints; ++j) {
    const JointSpec& s = sc.joints_true.joints[static_cast<std::size_t>(j)];
    const Vec3 centre_m =
        json_vec(joints["spheres"][static_cast<std::size_t>(j)]["pose"]["position"]);
    const Vec3 from_child =
        h->T_world_body[static_cast<std::size_t>(s.child_index)] * s.center_child * 1e-3;
    EXPECT_LT((centre_m - from_child).norm(), 1e-6) << s.name;
  }
  const auto ja = nlohmann::json::parse(foxglove::encode_joint_angles(*scene, *r, 42));
  ASSERT_EQ(ja["joints"].size(), static_cast<std::size_t>(kJoints));
  EXPECT_TRUE(ja["all_bodies_found"].get<bool>());
  for (int j = 0; j < kJoints; ++j) {
    const JointSpec& s = sc.joints_true.joints[static_cast<std::size_t>(j)];
    const auto& e = ja["joints"][static_cast<std::size_t>(j)];
    EXPECT_EQ(e["name"], s.name);
    EXPECT_EQ(e["type"], s.type == JointType::kHinge ? "hinge" : "ball");
    EXPECT_TRUE(e["valid"].get<bool>());
    ASSERT_EQ(e["angles_rad"].size(), s.type == JointType::kHinge ? 1u : 3u);
    EXPECT_NEAR(e["angles_rad"][0].get<double>(),
                h->out->angles.joints[static_cast<std::size_t>(j)].a0, 1e-6);
  }
}
#endif

}  // namespace
}  // namespace mocap::pipeline
