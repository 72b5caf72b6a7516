// The whole robot at the output seam (interfaces.md, "The whole robot": models of up to
// 32 bodies, every output carries them all): a hand-built frame of kMaxBodies = 32 found
// bodies (4 labelled markers each, 128 points), 31 valid ball joints and 8 cameras of 200
// blobs goes through make_frame_result (no allocation) into a FrameResult that holds all
// of it, and from there into the outputs' encoders: the UDP datagram (31 joint records,
// decoded by the client), the iceoryx payload (the same JointsMessage) and, when built,
// the Foxglove /tf and /markers JSON (32 transforms, 32 body labels, 128 markers).
// (ROS 2 /tf and /joint_states with 32 bodies: tests/publish/test_ros2.cpp.)
#include <gtest/gtest.h>

#include <memory>
#include <string>
#include <vector>

#include "client/datagram.h"
#include "pipeline/frame_result_builder.h"
#include "tests/support/alloc_counter.h"
#ifdef MOCAP_HAVE_FOXGLOVE
#include <nlohmann/json.hpp>

#include "pipeline/foxglove/encode.h"
#endif

namespace mocap::pipeline {
namespace {

constexpr int kBodies = kMaxBodies;  // 32
constexpr int kMarkersPerBody = 4;
constexpr int kCameras = 8;
constexpr int kBlobsPerCamera = 200;  // a humanoid and a half, plus strays

struct WholeRobot {
  TargetSet targets;
  std::unique_ptr<FrameOutput> out = std::make_unique<FrameOutput>();

  WholeRobot() {
    for (int b = 0; b < kBodies; ++b) {
      MarkerTarget t;
      t.name = "body" + std::to_string(b);
      for (int k = 0; k < kMarkersPerBody; ++k)
        t.markers_body.emplace_back(40.0 * (k == 1), 50.0 * (k == 2), 60.0 * (k == 3) + b);
      targets.bodies.push_back(t);
    }
    for (int c = 0; c < kCameras; ++c) {
      detect::BlobList blobs(512);
      for (int i = 0; i < kBlobsPerCamera; ++i) {
        detect::Blob blob;
        blob.x_px = 3.0 * i + c;
        blob.y_px = 2.0 * i;
        blob.area_px = 20.0f;
        EXPECT_TRUE(blobs.push_back(blob));
      }
      out->blobs.push_back(std::move(blobs));
      out->camera_present[static_cast<std::size_t>(c)] = true;
    }
    out->points.set_capacity(kMaxPoints);
    out->poses.count = kBodies;
    out->poses.found = kBodies;
    for (int b = 0; b < kBodies; ++b) {
      BodyPose& pose = out->poses.bodies[static_cast<std::size_t>(b)];
      pose.found = true;
      pose.T_world_body = Iso3::Identity();
      pose.T_world_body.translate(Vec3(100.0 * b, -50.0, 1500.0));
      pose.markers = kMarkersPerBody;
      pose.rms_mm = 0.3;
      pose.point_index_of_marker.fill(-1);
      for (int k = 0; k < kMarkersPerBody; ++k) {
        const int index = out->points.size();
        Point3 p;
        p.X_world =
            pose.T_world_body *
            targets.bodies[static_cast<std::size_t>(b)].markers_body[static_cast<std::size_t>(k)];
        p.reproj_px = 0.2;
        p.reported = true;
        p.blob_index[static_cast<std::size_t>(index % kCameras)] = static_cast<std::int16_t>(index);
        p.blob_index[static_cast<std::size_t>((index + 1) % kCameras)] =
            static_cast<std::int16_t>(index);
        EXPECT_TRUE(out->points.push_back(p));
        pose.point_index_of_marker[static_cast<std::size_t>(k)] = static_cast<std::int16_t>(index);
      }
    }
    out->angles.joints.resize(kBodies - 1);
    for (int j = 0; j < kBodies - 1; ++j) {
      kinematics::JointAngle& a = out->angles.joints[static_cast<std::size_t>(j)];
      a.valid = true;
      a.type = JointType::kBall;
      a.a0 = 0.01 * j;
      a.solved_by = client::SolvedBy::kPoses;
    }
  }
};

TEST(WholeRobot, ThirtyTwoBodiesFillTheFrameResult) {
  WholeRobot robot;
  auto r = std::make_unique<publish::FrameResult>();
  auto labelled = std::make_unique<LabelledMarkers>();
  {
    test::AllocationScope scope;
    make_frame_result(5, 777, robot.targets, *robot.out, *labelled, *r);
    EXPECT_EQ(scope.count(), 0u);
  }
  EXPECT_EQ(r->body_count, kBodies);
  for (int b = 0; b < kBodies; ++b) {
    EXPECT_EQ(r->bodies[static_cast<std::size_t>(b)].found, 1) << b;
    EXPECT_DOUBLE_EQ(r->bodies[static_cast<std::size_t>(b)].t_world_body_mm[0], 100.0 * b);
  }
  EXPECT_EQ(r->marker_count, kBodies * kMarkersPerBody);
  EXPECT_EQ(r->markers[static_cast<std::size_t>(r->marker_count - 1)].body, kBodies - 1);
  EXPECT_EQ(r->point_count, kBodies * kMarkersPerBody);
  EXPECT_EQ(r->joints.joint_count, kBodies - 1);
  EXPECT_EQ(r->joints.flags & client::kFlagAllBodiesFound, client::kFlagAllBodiesFound);
  EXPECT_EQ(r->camera_count, kCameras);
  int marker_blobs = 0;
  for (int c = 0; c < kCameras; ++c) {
    const publish::CameraBlobs& cb = r->cameras[static_cast<std::size_t>(c)];
    EXPECT_EQ(cb.count, kBlobsPerCamera) << "every blob of camera " << c;
    for (int i = 0; i < cb.count; ++i)
      marker_blobs += r->blobs_of(c)[i].use == static_cast<std::uint8_t>(publish::BlobUse::kMarker);
  }
  EXPECT_EQ(marker_blobs, 2 * kBodies * kMarkersPerBody);  // two views per marker
}

TEST(WholeRobot, EveryJointReachesTheDatagramAndTheIceoryxPayload) {
  WholeRobot robot;
  auto r = std::make_unique<publish::FrameResult>();
  auto labelled = std::make_unique<LabelledMarkers>();
  make_frame_result(9, 1234, robot.targets, *robot.out, *labelled, *r);
  // iceoryx publishes r->joints as its payload: the whole JointsMessage, 31 records used.
  static_assert(client::kMaxJoints >= kMaxBodies - 1, "a 32-body tree has 31 joints");
  std::vector<std::uint8_t> buf(client::kMaxDatagramBytes);
  const std::size_t n = client::encode_datagram(r->joints, buf.data(), buf.size());
  ASSERT_EQ(n, client::datagram_size(kBodies - 1));
  client::JointsMessage back;
  ASSERT_EQ(client::decode_datagram(buf.data(), n, back), client::DecodeStatus::kOk);
  EXPECT_EQ(back.sequence, 9u);
  EXPECT_EQ(back.capture_ns, 1234);
  ASSERT_EQ(back.joint_count, kBodies - 1);
  for (int j = 0; j < kBodies - 1; ++j) {
    EXPECT_EQ(back.joints[j].index, j);
    EXPECT_EQ(back.joints[j].valid, 1);
    EXPECT_FLOAT_EQ(back.joints[j].a[0], static_cast<float>(0.01 * j));
  }
}

#ifdef MOCAP_HAVE_FOXGLOVE
TEST(WholeRobot, FoxgloveTransformsAndSceneCarryEveryBody) {
  WholeRobot robot;
  auto r = std::make_unique<publish::FrameResult>();
  auto labelled = std::make_unique<LabelledMarkers>();
  make_frame_result(3, 1000, robot.targets, *robot.out, *labelled, *r);
  auto scene = foxglove::make_scene(robot.targets, nullptr);
  ASSERT_TRUE(scene) << scene.error().message;
  const auto tf = nlohmann::json::parse(foxglove::encode_frame_transforms(*scene, *r, 1000));
  ASSERT_EQ(tf["transforms"].size(), static_cast<std::size_t>(kBodies));
  EXPECT_EQ(tf["transforms"][kBodies - 1]["child_frame_id"], "body31");
  const auto su = nlohmann::json::parse(foxglove::encode_scene_update(*scene, *r, 1000));
  std::size_t labels = 0, markers = 0;
  for (const auto& e : su["entities"]) {
    if (e["id"] == "bodies") labels = e["texts"].size();
    if (e["id"] == "markers") markers = e["spheres"].size();
  }
  EXPECT_EQ(labels, static_cast<std::size_t>(kBodies));
  EXPECT_EQ(markers, static_cast<std::size_t>(kBodies * kMarkersPerBody));
}
#endif

}  // namespace
}  // namespace mocap::pipeline
