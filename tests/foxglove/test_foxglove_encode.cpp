// Tests of the live view's scene model and encoders (pipeline/foxglove/scene.h,
// encode.h): metres, frames and quaternion order of /tf, the SceneUpdate entities
// (points, markers coloured by body, joint centres and hinge axes posed in the world),
// the joint angles, the cameras' blob overlays (blob_overlay.h), and robustness to
// damaged counts and non-finite values.
#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <nlohmann/json.hpp>

#include "core/camera_set.h"
#include "pipeline/foxglove/blob_overlay.h"
#include "pipeline/foxglove/encode.h"

namespace mocap::foxglove {
namespace {

using nlohmann::json;

TargetSet two_bodies() {
  TargetSet t;
  t.marker_diameter_mm = 10.0;
  t.bodies.push_back({"upper_arm", {Vec3(0, 0, 0), Vec3(50, 0, 0), Vec3(0, 50, 0)}});
  t.bodies.push_back({"forearm", {Vec3(0, 0, 0), Vec3(40, 0, 0), Vec3(0, 40, 0)}});
  return t;
}

JointModel elbow() {
  JointModel m;
  JointSpec j;
  j.name = "elbow";
  j.type = JointType::kHinge;
  j.parent = "upper_arm";
  j.child = "forearm";
  j.parent_index = 0;
  j.child_index = 1;
  j.calibrated = true;
  j.center_parent = Vec3(100, 0, 0);
  j.axis_parent = Vec3(0, 0, 2);  // normalised by make_scene
  m.joints.push_back(j);
  return m;
}

// Body 0 rotated 90 deg about z and moved to (1000, 2000, 3000) mm; body 1 not found.
publish::FrameResult frame_with_pose() {
  publish::FrameResult f;
  f.body_count = 2;
  f.bodies[0].found = 1;
  const double h = std::sqrt(0.5);
  f.bodies[0].q_world_body = {h, 0.0, 0.0, h};  // qw, qx, qy, qz
  f.bodies[0].t_world_body_mm = {1000.0, 2000.0, 3000.0};
  f.bodies[1].found = 0;
  f.marker_count = 2;
  f.markers[0] = publish::ResultMarker{0, 1, {0, 0}, 0.1f, {{1000.0f, 2050.0f, 3000.0f}}};
  f.markers[1] = publish::ResultMarker{1, 0, {0, 0}, 0.1f, {{10.0f, 20.0f, 30.0f}}};
  f.point_count = 3;
  f.points[2].X_world_mm = {{-500.0f, 0.0f, 250.0f}};
  return f;
}

TEST(FoxgloveScene, BuildsBodiesAndJointsAndRejectsBadNames) {
  const TargetSet t = two_bodies();
  const JointModel m = elbow();
  auto scene = make_scene(t, &m);
  ASSERT_TRUE(scene.ok()) << scene.error().message;
  ASSERT_EQ(scene->bodies.size(), 2u);
  EXPECT_EQ(scene->world_frame, "mocap");
  EXPECT_TRUE(scene->joints[0].calibrated);
  EXPECT_NEAR(scene->joints[0].axis_parent.z(), 1.0, 1e-12);
  const Rgba a = scene->bodies[0].colour, b = scene->bodies[1].colour;
  EXPECT_GT(std::fabs(a.r - b.r) + std::fabs(a.g - b.g) + std::fabs(a.b - b.b), 0.3);

  TargetSet bad = t;
  bad.bodies[1].name = "mocap";
  auto e = make_scene(bad, nullptr);
  ASSERT_FALSE(e.ok());
  EXPECT_NE(e.error().message.find("body 1"), std::string::npos) << e.error().message;
  JointModel broken = m;
  broken.joints[0].child_index = 5;
  EXPECT_FALSE(make_scene(t, &broken).ok());
}

TEST(FoxgloveEncode, FrameTransformsInMetresWithXyzwQuaternions) {
  const TargetSet t = two_bodies();
  const FoxgloveScene scene = make_scene(t, nullptr).value();
  const json j =
      json::parse(encode_frame_transforms(scene, frame_with_pose(), 1'700'000'000'123'456'789));
  ASSERT_EQ(j["transforms"].size(), 1u);  // only the found body
  const json& tf = j["transforms"][0];
  EXPECT_EQ(tf["parent_frame_id"], "mocap");
  EXPECT_EQ(tf["child_frame_id"], "upper_arm");
  EXPECT_EQ(tf["timestamp"]["sec"], 1'700'000'000);
  EXPECT_EQ(tf["timestamp"]["nsec"], 123'456'789);
  EXPECT_DOUBLE_EQ(tf["translation"]["x"].get<double>(), 1.0);
  EXPECT_DOUBLE_EQ(tf["translation"]["y"].get<double>(), 2.0);
  EXPECT_DOUBLE_EQ(tf["translation"]["z"].get<double>(), 3.0);
  EXPECT_NEAR(tf["rotation"]["z"].get<double>(), std::sqrt(0.5), 1e-12);
  EXPECT_NEAR(tf["rotation"]["w"].get<double>(), std::sqrt(0.5), 1e-12);
  EXPECT_NEAR(tf["rotation"]["x"].get<double>(), 0.0, 1e-12);
}

TEST(FoxgloveEncode, SceneUpdateHasPointsMarkersAndPosedJoints) {
  const TargetSet t = two_bodies();
  const JointModel m = elbow();
  const FoxgloveScene scene = make_scene(t, &m).value();
  const json j = json::parse(encode_scene_update(scene, frame_with_pose(), 5));
  ASSERT_EQ(j["entities"].size(), 4u);
  const json& points = j["entities"][0];
  const json& markers = j["entities"][1];
  const json& joints = j["entities"][3];
  EXPECT_EQ(points["id"], "points");
  EXPECT_EQ(points["frame_id"], "mocap");
  ASSERT_EQ(points["spheres"].size(), 3u);
  EXPECT_DOUBLE_EQ(points["spheres"][2]["pose"]["position"]["x"].get<double>(), -0.5);
  ASSERT_EQ(markers["spheres"].size(), 2u);
  EXPECT_DOUBLE_EQ(markers["spheres"][0]["size"]["x"].get<double>(), 0.01);  // 10 mm
  EXPECT_DOUBLE_EQ(markers["spheres"][0]["color"]["r"].get<double>(), scene.bodies[0].colour.r);
  EXPECT_DOUBLE_EQ(markers["spheres"][1]["color"]["g"].get<double>(), scene.bodies[1].colour.g);
  EXPECT_EQ(j["entities"][2]["texts"][0]["text"], "upper_arm");
  // Elbow centre (100,0,0) in upper_arm, rotated 90 deg about z: (0,100,0) + t.
  ASSERT_EQ(joints["spheres"].size(), 1u);
  const json& c = joints["spheres"][0]["pose"]["position"];
  EXPECT_NEAR(c["x"].get<double>(), 1.0, 1e-9);
  EXPECT_NEAR(c["y"].get<double>(), 2.1, 1e-9);
  EXPECT_NEAR(c["z"].get<double>(), 3.0, 1e-9);
  // The hinge arrow points along the world axis (z): +x rotated by its orientation.
  ASSERT_EQ(joints["arrows"].size(), 1u);
  const json& o = joints["arrows"][0]["pose"]["orientation"];
  const Quat q(o["w"].get<double>(), o["x"].get<double>(), o["y"].get<double>(),
               o["z"].get<double>());
  EXPECT_NEAR((q * Vec3::UnitX() - Vec3::UnitZ()).norm(), 0.0, 1e-9);
  // Every entity carries every field foxglove.SceneEntity requires.
  for (const char* key :
       {"timestamp", "frame_id", "id", "lifetime", "frame_locked", "metadata", "arrows", "cubes",
        "spheres", "cylinders", "lines", "triangles", "texts", "models"}) {
    EXPECT_TRUE(points.contains(key)) << key;
  }
}

TEST(FoxgloveEncode, JointAnglesWithNamesQualityAndFiniteNumbers) {
  const TargetSet t = two_bodies();
  const JointModel m = elbow();
  const FoxgloveScene scene = make_scene(t, &m).value();
  publish::FrameResult f;
  f.joints.sequence = 42;
  f.joints.flags = client::kFlagAllBodiesFound;
  f.joints.joint_count = 2;
  f.joints.joints[0] = client::JointRecord{0, 1, 1, {0.5f, 0.0f, 0.0f}, {1, 0, 0, 0}};
  f.joints.quality[0].solved_by = 2;
  f.joints.quality[0].sd_rad[0] = 0.01f;
  f.joints.joints[1] = client::JointRecord{7, 0, 0, {NAN, 0.25f, INFINITY}, {1, 0, 0, 0}};
  const json j = json::parse(encode_joint_angles(scene, f, 0));
  EXPECT_EQ(j["sequence"], 42);
  EXPECT_EQ(j["all_bodies_found"], true);
  ASSERT_EQ(j["joints"].size(), 2u);
  EXPECT_EQ(j["joints"][0]["name"], "elbow");
  EXPECT_EQ(j["joints"][0]["type"], "hinge");
  EXPECT_EQ(j["joints"][0]["solved_by"], "chain");
  ASSERT_EQ(j["joints"][0]["angles_rad"].size(), 1u);
  EXPECT_NEAR(j["joints"][0]["angles_rad"][0].get<double>(), 0.5, 1e-7);
  EXPECT_EQ(j["joints"][1]["name"], "joint7");
  EXPECT_EQ(j["joints"][1]["valid"], false);
  ASSERT_EQ(j["joints"][1]["angles_rad"].size(), 3u);
  EXPECT_TRUE(j["joints"][1]["angles_rad"][0].is_number());  // NaN written as 0
  EXPECT_EQ(j["joints"][1]["angles_rad"][0].get<double>(), 0.0);
}

TEST(FoxgloveEncode, BodyStatesCarryQualityPoseAndVelocities) {
  const TargetSet t = two_bodies();
  const FoxgloveScene scene = make_scene(t, nullptr).value();
  publish::FrameResult f = frame_with_pose();
  f.joints.sequence = 9;
  f.bodies[0].markers = 4;
  f.bodies[0].rms_mm = 0.125f;
  f.bodies[0].velocity_valid = 1;
  f.bodies[0].v_world_mm_s = {{100.0f, -200.0f, 0.0f}};
  f.bodies[0].w_world_rad_s = {{0.0f, 0.0f, 1.5f}};
  const json j = json::parse(encode_body_states(scene, f, 0));
  EXPECT_EQ(j["sequence"], 9);
  EXPECT_EQ(j["frame_id"], "mocap");
  ASSERT_EQ(j["bodies"].size(), 2u);  // every body, found or not
  const json& b = j["bodies"][0];
  EXPECT_EQ(b["name"], "upper_arm");
  EXPECT_EQ(b["found"], true);
  EXPECT_EQ(b["markers"], 4);
  EXPECT_DOUBLE_EQ(b["rms_mm"].get<double>(), 0.125);
  EXPECT_DOUBLE_EQ(b["position"]["y"].get<double>(), 2.0);
  EXPECT_DOUBLE_EQ(b["velocity_m_s"][1].get<double>(), -0.2);
  EXPECT_DOUBLE_EQ(b["angular_velocity_rad_s"][2].get<double>(), 1.5);
  EXPECT_EQ(j["bodies"][1]["found"], false);
  EXPECT_FALSE(j["bodies"][1].contains("markers"));
  f.bodies[0].velocity_valid = 0;  // not known yet: null, never a stale value
  EXPECT_TRUE(json::parse(encode_body_states(scene, f, 0))["bodies"][0]["velocity_m_s"].is_null());
}

TEST(FoxgloveEncode, JointRatesWhenKnown) {
  const TargetSet t = two_bodies();
  const JointModel m = elbow();
  const FoxgloveScene scene = make_scene(t, &m).value();
  publish::FrameResult f;
  f.joints.joint_count = 1;
  f.joints.joints[0] = client::JointRecord{0, 1, 1, {0.5f, 0.0f, 0.0f}, {1, 0, 0, 0}};
  f.joints.rates[0].valid = 1;
  f.joints.rates[0].rate_rad_s[0] = 2.0f;
  f.joints.rates[0].sd_rad_s[0] = 0.25f;
  json j = json::parse(encode_joint_angles(scene, f, 0));
  ASSERT_EQ(j["joints"][0]["rate_rad_s"].size(), 1u);
  EXPECT_DOUBLE_EQ(j["joints"][0]["rate_rad_s"][0].get<double>(), 2.0);
  EXPECT_DOUBLE_EQ(j["joints"][0]["rate_sd_rad_s"][0].get<double>(), 0.25);
  f.joints.rates[0].valid = 0;
  j = json::parse(encode_joint_angles(scene, f, 0));
  EXPECT_TRUE(j["joints"][0]["rate_rad_s"].is_null());
}

TEST(FoxgloveEncode, DamagedCountsAreClamped) {
  const TargetSet t = two_bodies();
  const FoxgloveScene scene = make_scene(t, nullptr).value();
  publish::FrameResult f;
  f.body_count = 1000;
  f.marker_count = -3;
  f.point_count = 1 << 20;
  f.markers[0].body = 200;  // not a body of the scene
  f.joints.joint_count = 60000;
  EXPECT_NO_THROW(EXPECT_TRUE(json::parse(encode_frame_transforms(scene, f, -1)).is_object()));
  const json s = json::parse(encode_scene_update(scene, f, 0));
  EXPECT_EQ(s["entities"][0]["spheres"].size(),
            static_cast<std::size_t>(publish::kMaxResultPoints));
  EXPECT_EQ(s["entities"][1]["spheres"].size(), 0u);
  const json j = json::parse(encode_joint_angles(scene, f, 0));
  EXPECT_EQ(j["joints"].size(), static_cast<std::size_t>(client::kMaxJoints));
  EXPECT_EQ(json::parse(encode_body_states(scene, f, 0))["bodies"].size(), t.bodies.size());
}

Rig two_cameras() {
  Rig rig;
  for (const char* n : {"left", "right"}) {
    CameraModel c;
    c.name = n;
    c.width = 1032;
    c.height = 776;
    rig.cameras.push_back(c);
  }
  return rig;
}

TEST(FoxgloveEncode, ChannelsAdvertiseValidJsonSchemas) {
  const Rig rig = two_cameras();
  const auto channels = live_view_channels(make_scene(two_bodies(), nullptr, &rig).value());
  ASSERT_EQ(channels.size(), 6u);
  EXPECT_EQ(channels[0].topic, "/tf");
  EXPECT_EQ(channels[1].schema_name, "foxglove.SceneUpdate");
  EXPECT_EQ(channels[3].topic, "/bodies");
  EXPECT_EQ(channels[3].id, kChannelBodies);
  EXPECT_EQ(channels[4].topic, "/left/blobs");
  EXPECT_EQ(channels[5].id, kChannelBlobsFirst + 1);
  EXPECT_EQ(channels[5].schema_name, "foxglove.RawImage");
  EXPECT_EQ(live_view_channels(make_scene(two_bodies(), nullptr).value()).size(), 4u);
  for (const auto& c : channels) {
    const json s = json::parse(c.schema);
    EXPECT_EQ(s["type"], "object") << c.topic;
  }
}

// A rig of 8 cameras (the most a rig may have): one blob channel per camera, in rig
// order, ids consecutive after the fixed channels; each camera's overlay is its own.
TEST(FoxgloveEncode, EveryCameraOfAnEightCameraRigHasItsBlobChannel) {
  Rig rig;
  for (int k = 0; k < kMaxCameras; ++k) {
    CameraModel c;
    c.name = "cam" + std::to_string(k);
    c.width = 640 + 64 * k;  // sizes differ per camera
    c.height = 480;
    rig.cameras.push_back(c);
  }
  const FoxgloveScene scene = make_scene(two_bodies(), nullptr, &rig).value();
  const auto channels = live_view_channels(scene);
  ASSERT_EQ(channels.size(), 4u + static_cast<std::size_t>(kMaxCameras));
  for (int k = 0; k < kMaxCameras; ++k) {
    const ChannelInfo& ch = channels[4 + static_cast<std::size_t>(k)];
    EXPECT_EQ(ch.topic, "/cam" + std::to_string(k) + "/blobs");
    EXPECT_EQ(ch.id, kChannelBlobsFirst + static_cast<std::uint32_t>(k));
  }
  auto f = std::make_unique<publish::FrameResult>();
  f->camera_count = kMaxCameras;
  f->cameras[7].present = 1;
  const json last = json::parse(encode_blob_overlay(scene, *f, 7, 0));
  EXPECT_EQ(last["frame_id"], "cam7");
  EXPECT_EQ(last["width"], (640 + 64 * 7) / kBlobOverlayScale);
  EXPECT_TRUE(encode_blob_overlay(scene, *f, kMaxCameras, 0).empty());
}

}  // namespace
}  // namespace mocap::foxglove

namespace mocap::foxglove {
namespace {

std::string unbase64(const std::string& s) {
  std::string out;
  std::uint32_t v = 0;
  int bits = 0;
  for (char ch : s) {
    const std::string alphabet = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    const std::size_t k = alphabet.find(ch);
    if (k == std::string::npos) break;  // '=' padding
    v = (v << 6) | static_cast<std::uint32_t>(k);
    bits += 6;
    if (bits >= 8) {
      bits -= 8;
      out.push_back(static_cast<char>((v >> bits) & 0xFFu));
    }
  }
  return out;
}

TEST(FoxgloveBlobOverlay, Base64MatchesRfc4648) {
  EXPECT_EQ(base64(""), "");
  EXPECT_EQ(base64("f"), "Zg==");
  EXPECT_EQ(base64("fo"), "Zm8=");
  EXPECT_EQ(base64("foo"), "Zm9v");
  EXPECT_EQ(base64("foob"), "Zm9vYg==");
  EXPECT_EQ(base64("fooba"), "Zm9vYmE=");
  EXPECT_EQ(base64("foobar"), "Zm9vYmFy");
  std::string all;
  for (int i = 0; i < 256; ++i) all.push_back(static_cast<char>(i));
  EXPECT_EQ(unbase64(base64(all)), all);  // round trip over every byte value
}

// A marker blob, a point blob and an unused blob land where they are, scaled 1/4, in
// their grey levels; the border outlines the image; damaged blobs are skipped.
TEST(FoxgloveBlobOverlay, DrawsEachBlobWhereTheCameraSeesItInItsGreyLevel) {
  const Rig rig = two_cameras();
  const FoxgloveScene scene = make_scene(two_bodies(), nullptr, &rig).value();
  auto f = std::make_unique<publish::FrameResult>();
  f->camera_count = 2;
  publish::CameraBlobs& cb = f->cameras[1];
  cb.present = 1;
  cb.count = 5;
  cb.first = 7;  // anywhere in the frame's blobs
  publish::ResultBlob* const blobs = f->blobs_of(1);
  blobs[0] = {400.0f, 200.0f, 12.0f, static_cast<std::uint8_t>(publish::BlobUse::kMarker), 1, 2, 0};
  blobs[1] = {800.0f, 600.0f, 8.0f, static_cast<std::uint8_t>(publish::BlobUse::kPoint), 0, 0, 0};
  blobs[2] = {101.0f, 101.0f, 2.0f, static_cast<std::uint8_t>(publish::BlobUse::kUnused), 0, 0, 0};
  blobs[3] = {NAN, 5.0f, 8.0f, 0, 0, 0, 0};
  blobs[4] = {-1e30f, 1e30f, 1e30f, 0, 0, 0, 0};
  const json j = json::parse(encode_blob_overlay(scene, *f, 1, 1500000000));
  EXPECT_EQ(j["frame_id"], "right");
  EXPECT_EQ(j["encoding"], "mono8");
  EXPECT_EQ(j["timestamp"]["sec"], 1);
  EXPECT_EQ(j["timestamp"]["nsec"], 500000000);
  const int w = j["width"], h = j["height"];
  EXPECT_EQ(w, 1032 / kBlobOverlayScale);
  EXPECT_EQ(h, 776 / kBlobOverlayScale);
  EXPECT_EQ(j["step"], w);
  const std::string px = unbase64(j["data"].get<std::string>());
  ASSERT_EQ(px.size(), static_cast<std::size_t>(w * h));
  const auto at = [&](int x, int y) {
    return static_cast<std::uint8_t>(px[static_cast<std::size_t>(y * w + x)]);
  };
  EXPECT_EQ(at(100, 50), kGreyMarker);
  EXPECT_EQ(at(99, 49), kGreyMarker);  // radius 1.5 px: the neighbours too
  EXPECT_EQ(at(200, 150), kGreyPoint);
  EXPECT_EQ(at(25, 25), kGreyUnused);  // a 2 px blob still covers its pixel
  EXPECT_EQ(at(0, 0), kGreyBorder);
  EXPECT_EQ(at(w - 1, h / 2), kGreyBorder);
  EXPECT_EQ(at(150, 100), 0);
  int lit = 0;
  for (unsigned char v : px) lit += v > kGreyBorder ? 1 : 0;
  EXPECT_LT(lit, 30);  // three small discs, nothing from the damaged blobs
  // No such camera; a frame without blobs still gives the border.
  EXPECT_TRUE(encode_blob_overlay(scene, *f, 2, 0).empty());
  f->camera_count = 0;
  const json e = json::parse(encode_blob_overlay(scene, *f, 0, 0));
  EXPECT_EQ(unbase64(e["data"].get<std::string>()).size(), static_cast<std::size_t>(w * h));
}

// Camera names become topics: a name that is not a topic segment is a one-line error.
TEST(FoxgloveBlobOverlay, CameraNamesMustBeTopicSegments) {
  Rig rig = two_cameras();
  rig.cameras[1].name = "right/../x";
  const auto e = make_scene(two_bodies(), nullptr, &rig);
  ASSERT_FALSE(e.ok());
  EXPECT_NE(e.error().message.find("camera 1"), std::string::npos) << e.error().message;
  EXPECT_EQ(e.error().message.find('\n'), std::string::npos);
}

}  // namespace
}  // namespace mocap::foxglove
