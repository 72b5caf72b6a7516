// make_frame_result: from a hand-built FrameOutput (two bodies, one found, four 3D
// points, a ball and a hinge joint) to the FrameResult every sink receives: joints as
// the datagram expects them (validity, angles, quality solved-by), the found body's pose
// as qw>=0 quaternion + translation, its labelled markers with the residual to the
// posed model marker (unmatched markers left out), the points with reprojection error
// and camera count, and each camera's blobs with what they became; which points a body
// claimed (ResultPoint::labelled, also behind points that are not reported); no allocation;
// 12 cameras share the result's blobs.
#include <gtest/gtest.h>

#include <cmath>
#include <memory>

#include "pipeline/frame_result_builder.h"
#include "tests/support/alloc_counter.h"

namespace mocap::pipeline {
namespace {

TEST(FrameResultBuilder, JointsPosesLabelledMarkersAndPoints) {
  TargetSet targets;
  for (const char* n : {"upper_arm", "forearm"}) {
    MarkerTarget t;
    t.name = n;
    t.markers_body = {Vec3(0, 0, 0), Vec3(40, 0, 0), Vec3(0, 50, 0)};
    targets.bodies.push_back(t);
  }
  auto out = std::make_unique<FrameOutput>();
  out->points.set_capacity(8);
  Iso3 T = Iso3::Identity();
  T.translate(Vec3(100, 200, 1500));
  T.rotate(Eigen::AngleAxisd(M_PI / 2, Vec3::UnitZ()));
  // Points 0..2: markers 0, 2 of body 0 (1 mm off in x for marker 2), a stray; 3: no.
  const Vec3 p0 = T * targets.bodies[0].markers_body[0];
  const Vec3 p2 = T * targets.bodies[0].markers_body[2] + Vec3(1, 0, 0);
  for (const Vec3& X : {p0, Vec3(5, 5, 5), p2}) {
    Point3 p;
    p.X_world = X;
    p.reproj_px = 0.25;
    p.blob_index = {3, 4, -1, -1};
    p.reported = true;
    ASSERT_TRUE(out->points.push_back(p));
  }
  Point3 lost;  // a candidate that lost its blobs to a better one: not a point
  lost.X_world = Vec3(9, 9, 9);
  lost.blob_index = {5, 6, -1, -1};
  ASSERT_TRUE(out->points.push_back(lost));
  out->poses.count = 2;
  out->poses.found = 1;
  BodyPose& b0 = out->poses.bodies[0];
  b0.found = true;
  b0.T_world_body = T;
  b0.markers = 2;
  b0.rms_mm = 0.7;
  b0.point_index_of_marker.fill(-1);
  b0.point_index_of_marker[0] = 0;
  b0.point_index_of_marker[2] = 2;
  out->poses.bodies[1].found = false;
  out->angles.joints.resize(2);
  out->angles.joints[0].valid = true;
  out->angles.joints[0].type = JointType::kBall;
  out->angles.joints[0].a0 = 0.1;
  out->angles.joints[0].a1 = -0.2;
  out->angles.joints[0].a2 = 0.3;
  out->angles.joints[0].solved_by = client::SolvedBy::kPoses;
  out->angles.joints[0].sd_rad = {0.001, 0.002, 0.003};
  out->angles.joints[1].valid = false;
  out->angles.joints[1].type = JointType::kHinge;

  auto r = std::make_unique<publish::FrameResult>();
  auto labelled = std::make_unique<LabelledMarkers>();
  {
    test::AllocationScope scope;
    make_frame_result(7, 123456, targets, *out, *labelled, *r);
    EXPECT_EQ(scope.count(), 0u);
  }
  EXPECT_EQ(r->joints.sequence, 7u);
  EXPECT_EQ(r->joints.capture_ns, 123456);
  EXPECT_EQ(r->joints.flags, 0u);  // one body of two
  ASSERT_EQ(r->joints.joint_count, 2);
  EXPECT_EQ(r->joints.joints[0].valid, 1);
  EXPECT_FLOAT_EQ(r->joints.joints[0].a[1], -0.2f);
  EXPECT_EQ(r->joints.joints[1].valid, 0);
  EXPECT_EQ(r->joints.joints[1].type, static_cast<std::uint8_t>(client::JointKind::kHinge));
  EXPECT_EQ(r->joints.quality[0].solved_by, static_cast<std::uint8_t>(client::SolvedBy::kPoses));
  EXPECT_EQ(r->joints.quality[1].solved_by, static_cast<std::uint8_t>(client::SolvedBy::kNone));
  EXPECT_FLOAT_EQ(r->joints.quality[0].sd_rad[2], 0.003f);

  ASSERT_EQ(r->body_count, 2);
  EXPECT_EQ(r->bodies[0].found, 1);
  EXPECT_EQ(r->bodies[0].markers, 2);
  EXPECT_FLOAT_EQ(r->bodies[0].rms_mm, 0.7f);
  EXPECT_NEAR(r->bodies[0].q_world_body[0], std::sqrt(0.5), 1e-12);  // qw
  EXPECT_NEAR(r->bodies[0].q_world_body[3], std::sqrt(0.5), 1e-12);  // qz
  EXPECT_DOUBLE_EQ(r->bodies[0].t_world_body_mm[2], 1500.0);
  EXPECT_EQ(r->bodies[1].found, 0);

  ASSERT_EQ(r->marker_count, 2);
  EXPECT_EQ(r->markers[0].body, 0);
  EXPECT_EQ(r->markers[0].marker, 0);
  EXPECT_NEAR(r->markers[0].residual_mm, 0.0f, 1e-4f);
  EXPECT_EQ(r->markers[1].marker, 2);
  EXPECT_NEAR(r->markers[1].residual_mm, 1.0f, 1e-4f);
  EXPECT_FLOAT_EQ(r->markers[1].X_world_mm[0], static_cast<float>(p2.x()));

  ASSERT_EQ(r->point_count, 3);
  EXPECT_FLOAT_EQ(r->points[1].X_world_mm[1], 5.0f);
  EXPECT_FLOAT_EQ(r->points[1].reproj_px, 0.25f);
  EXPECT_EQ(r->points[1].cameras, 2);
}

// Each camera's blobs say what they became: blob 0 of both cameras is a labelled marker
// (point 0 of body 0), blob 1 of camera 0 with blob 2 of camera 1 a point no body
// claimed, the others unused; a camera whose frame was missing says so.
TEST(FrameResultBuilder, BlobsSayWhatTheyBecame) {
  TargetSet targets;
  MarkerTarget t;
  t.name = "torso";
  t.markers_body = {Vec3(0, 0, 0), Vec3(40, 0, 0), Vec3(0, 50, 0)};
  targets.bodies.push_back(t);
  auto out = std::make_unique<FrameOutput>();
  out->points.set_capacity(4);
  out->blobs.resize(2);
  for (int c = 0; c < 2; ++c) {
    out->blobs[static_cast<std::size_t>(c)] = detect::BlobList(8);
    out->camera_present[static_cast<std::size_t>(c)] = c == 0;
    for (int i = 0; i < 4; ++i) {
      detect::Blob b;
      b.x_px = 100.0 + 10.0 * i;
      b.y_px = 50.0 + c;
      b.area_px = static_cast<float>(M_PI * 25.0);  // a disc of 10 px diameter
      ASSERT_TRUE(out->blobs[static_cast<std::size_t>(c)].push_back(b));
    }
  }
  Point3 p;
  p.reported = true;
  p.X_world = Vec3(0, 0, 1000);
  p.blob_index = {0, 0, -1, -1};
  ASSERT_TRUE(out->points.push_back(p));
  p.X_world = Vec3(300, 0, 1000);
  p.blob_index = {1, 2, -1, -1};
  ASSERT_TRUE(out->points.push_back(p));
  p.blob_index = {7, 99, -1, -1};  // damaged indices are ignored
  ASSERT_TRUE(out->points.push_back(p));
  p.reported = false;  // a candidate that lost to a better one leaves its blobs unused
  p.blob_index = {3, 1, -1, -1};
  ASSERT_TRUE(out->points.push_back(p));
  out->poses.count = 1;
  out->poses.found = 1;
  BodyPose& b0 = out->poses.bodies[0];
  b0.found = true;
  b0.T_world_body = Iso3::Identity();
  b0.T_world_body.translate(Vec3(0, 0, 1000));
  b0.markers = 1;
  b0.point_index_of_marker.fill(-1);
  b0.point_index_of_marker[0] = 0;

  auto r = std::make_unique<publish::FrameResult>();
  auto labelled = std::make_unique<LabelledMarkers>();
  {
    test::AllocationScope scope;
    make_frame_result(1, 0, targets, *out, *labelled, *r);
    EXPECT_EQ(scope.count(), 0u);
  }
  using publish::BlobUse;
  const auto use = [&](int c, int i) { return static_cast<BlobUse>(r->blobs_of(c)[i].use); };
  ASSERT_EQ(r->camera_count, 2);
  EXPECT_EQ(r->cameras[0].present, 1);
  EXPECT_EQ(r->cameras[1].present, 0);
  ASSERT_EQ(r->cameras[0].count, 4);
  EXPECT_FLOAT_EQ(r->blobs_of(0)[3].x_px, 130.0f);
  EXPECT_FLOAT_EQ(r->blobs_of(1)[0].y_px, 51.0f);
  EXPECT_NEAR(r->blobs_of(0)[0].diameter_px, 10.0f, 1e-4f);
  EXPECT_EQ(use(0, 0), BlobUse::kMarker);
  EXPECT_EQ(use(1, 0), BlobUse::kMarker);
  EXPECT_EQ(r->blobs_of(0)[0].body, 0);
  EXPECT_EQ(r->blobs_of(0)[0].marker, 0);
  EXPECT_EQ(use(0, 1), BlobUse::kPoint);
  EXPECT_EQ(use(1, 2), BlobUse::kPoint);
  EXPECT_EQ(use(0, 2), BlobUse::kUnused);
  EXPECT_EQ(use(1, 1), BlobUse::kUnused);
  EXPECT_EQ(use(0, 3), BlobUse::kUnused);
}

// More than 8 cameras share the result's blobs (kMaxResultBlobTotal): 12 cameras of 200
// blobs keep 2048 / 12 = 170 each, in consecutive ranges, and a point seen by cameras 9
// and 11 (camera mask bits above 7) marks its blobs there.
TEST(FrameResultBuilder, TwelveCamerasShareTheBlobsAndMarkTheirUses) {
  constexpr int kCams = 12;
  TargetSet targets;
  auto out = std::make_unique<FrameOutput>();
  out->points.set_capacity(4);
  out->blobs.resize(kCams);
  for (int c = 0; c < kCams; ++c) {
    out->blobs[static_cast<std::size_t>(c)] = detect::BlobList(256);
    out->camera_present[static_cast<std::size_t>(c)] = true;
    for (int i = 0; i < 200; ++i) {
      detect::Blob b;
      b.x_px = 1000.0 * c + i;
      ASSERT_TRUE(out->blobs[static_cast<std::size_t>(c)].push_back(b));
    }
  }
  Point3 p;
  p.reported = true;
  p.blob_index[9] = 5;
  p.blob_index[11] = 169;
  ASSERT_TRUE(out->points.push_back(p));
  p.blob_index = BlobRefs{};
  p.blob_index[10] = 170;  // beyond camera 10's share: left out
  p.blob_index[11] = 3;
  ASSERT_TRUE(out->points.push_back(p));
  auto r = std::make_unique<publish::FrameResult>();
  auto labelled = std::make_unique<LabelledMarkers>();
  make_frame_result(1, 0, targets, *out, *labelled, *r);
  ASSERT_EQ(r->camera_count, kCams);
  EXPECT_EQ(publish::result_blobs_per_camera(kCams), 170);
  for (int c = 0; c < kCams; ++c) {
    EXPECT_EQ(r->cameras[static_cast<std::size_t>(c)].count, 170) << c;
    EXPECT_EQ(r->cameras[static_cast<std::size_t>(c)].first, 170 * c) << c;
    EXPECT_FLOAT_EQ(r->blobs_of(c)[169].x_px, 1000.0f * static_cast<float>(c) + 169.0f) << c;
  }
  using publish::BlobUse;
  const auto use = [&](int c, int i) { return static_cast<BlobUse>(r->blobs_of(c)[i].use); };
  EXPECT_EQ(use(9, 5), BlobUse::kPoint);
  EXPECT_EQ(use(11, 169), BlobUse::kPoint);
  EXPECT_EQ(use(11, 3), BlobUse::kPoint);
  EXPECT_EQ(use(9, 4), BlobUse::kUnused);
  EXPECT_EQ(use(10, 169), BlobUse::kUnused);
  EXPECT_EQ(use(8, 5), BlobUse::kUnused);
}

// ResultPoint::labelled: the points a body claimed, mapped through the points that are
// not reported (result.points skips them): out.points = {lost, marker 0, stray, marker
// 2} -> result.points = {marker 0: 1, stray: 0, marker 2: 1}; a reused result is reset.
TEST(FrameResultBuilder, PointsSayWhetherABodyClaimedThem) {
  TargetSet targets;
  MarkerTarget t;
  t.name = "torso";
  t.markers_body = {Vec3(0, 0, 0), Vec3(40, 0, 0), Vec3(0, 50, 0)};
  targets.bodies.push_back(t);
  auto out = std::make_unique<FrameOutput>();
  out->points.set_capacity(4);
  Iso3 T = Iso3::Identity();
  T.translate(Vec3(0, 0, 1000));
  Point3 p;
  p.reported = false;  // a candidate that lost its blobs to a better one
  p.X_world = Vec3(1, 1, 1);
  ASSERT_TRUE(out->points.push_back(p));
  p.reported = true;
  for (const Vec3& X : {T * t.markers_body[0], Vec3(500, 0, 900), T * t.markers_body[2]}) {
    p.X_world = X;
    ASSERT_TRUE(out->points.push_back(p));
  }
  out->poses.count = 1;
  out->poses.found = 1;
  BodyPose& b0 = out->poses.bodies[0];
  b0.found = true;
  b0.T_world_body = T;
  b0.markers = 2;
  b0.point_index_of_marker.fill(-1);
  b0.point_index_of_marker[0] = 1;
  b0.point_index_of_marker[2] = 3;

  auto r = std::make_unique<publish::FrameResult>();
  for (publish::ResultPoint& rp : r->points) rp.labelled = 1;  // the slot's previous frame
  auto labelled = std::make_unique<LabelledMarkers>();
  {
    test::AllocationScope scope;
    make_frame_result(1, 0, targets, *out, *labelled, *r);
    EXPECT_EQ(scope.count(), 0u);
  }
  ASSERT_EQ(r->point_count, 3);
  ASSERT_EQ(r->marker_count, 2);
  EXPECT_EQ(r->points[0].labelled, 1);
  EXPECT_FLOAT_EQ(r->points[1].X_world_mm[0], 500.0f);
  EXPECT_EQ(r->points[1].labelled, 0);
  EXPECT_EQ(r->points[2].labelled, 1);
  EXPECT_FLOAT_EQ(r->points[2].X_world_mm[1], 50.0f);
}

}  // namespace
}  // namespace mocap::pipeline
