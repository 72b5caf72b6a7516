// Test support: one full frame of the whole-body humanoid (docs/simulator.md, "The
// humanoid": 15 bodies, 14 joints, 71 markers) for the outputs' tests, built in memory
// from the simulator's scene and true model (sim::make_scene, no rendering, so it is
// cheap under ASan): a random configuration inside every joint's range, the body poses
// of the forward kinematics, every marker posed as a 3D point (plus two stray points no
// body claims), each point's blobs in the cameras that see it (projected), and the joint
// angles of the true model computed by the tracker's JointAngleSolver from those poses.
// make_result() runs the pipeline's make_frame_result on it, as the identify stage does.
#pragma once

#include <gtest/gtest.h>

#include <memory>
#include <random>
#include <vector>

#include "camera/camera_model.h"
#include "kinematics/joint_angles.h"
#include "pipeline/frame_result_builder.h"
#include "sim/simulate.h"

namespace mocap::testing {

struct HumanoidFrame {
  sim::SimScene scene;
  std::vector<Iso3> T_world_body;  // the true poses (world), per body
  std::unique_ptr<FrameOutput> out = std::make_unique<FrameOutput>();
  int stray_points = 2;  // points after the 71 markers, no body's

  // The frame result every output receives (sequence 7, capture time `capture_ns`).
  std::unique_ptr<publish::FrameResult> make_result(std::int64_t capture_ns) const {
    auto r = std::make_unique<publish::FrameResult>();
    auto labelled = std::make_unique<LabelledMarkers>();
    pipeline::make_frame_result(7, capture_ns, scene.targets, *out, *labelled, *r);
    return r;
  }
};

inline std::unique_ptr<HumanoidFrame> make_humanoid_frame(int cameras, std::uint32_t seed) {
  auto h = std::make_unique<HumanoidFrame>();
  sim::SimOptions o;
  o.scene = sim::SceneKind::kHumanoid;
  o.cameras = cameras;
  auto scene = sim::make_scene(o);
  EXPECT_TRUE(scene.ok()) << (scene.ok() ? "" : scene.error().message);
  if (!scene.ok()) return h;
  h->scene = std::move(scene).value();
  const sim::SimScene& sc = h->scene;
  sim::JointConfig config = sim::make_config(sc);
  std::mt19937 rng(seed);
  for (int k = 0; k < sc.joint_count(); ++k) {
    const sim::SimJoint& j = sc.tree[static_cast<std::size_t>(k)];
    for (int a = 0; a < 3; ++a) {
      std::uniform_real_distribution<double> u(j.lower_rad[a], j.upper_rad[a]);
      config.q_rad[static_cast<std::size_t>(k)][a] = u(rng);
    }
  }
  sim::SceneState state = sim::make_state(sc);
  sim::apply_config(sc, config, state);
  h->T_world_body = state.T_world_body;

  FrameOutput& out = *h->out;
  const int n_cam = static_cast<int>(sc.rig.cameras.size());
  out.blobs.clear();
  for (int c = 0; c < n_cam; ++c) {
    out.blobs.emplace_back(256);
    out.camera_present[static_cast<std::size_t>(c)] = true;
  }
  out.points.set_capacity(kMaxPoints);
  auto add_point = [&](const Vec3& X) {
    Point3 p;
    p.X_world = X;
    p.reproj_px = 0.15;
    p.reported = true;
    for (int c = 0; c < n_cam; ++c) {
      Vec2 px;
      const CameraModel& cam = sc.rig.cameras[static_cast<std::size_t>(c)];
      if (!project(cam, X, px) || px.x() < 0 || px.y() < 0 || px.x() > cam.width - 1 ||
          px.y() > cam.height - 1)
        continue;
      detect::Blob b;
      b.x_px = px.x();
      b.y_px = px.y();
      b.area_px = 60.0f;
      detect::BlobList& list = out.blobs[static_cast<std::size_t>(c)];
      p.blob_index[static_cast<std::size_t>(c)] = static_cast<std::int16_t>(list.size());
      EXPECT_TRUE(list.push_back(b));
    }
    EXPECT_TRUE(out.points.push_back(p));
    return out.points.size() - 1;
  };
  const int bodies = sc.body_count();
  out.poses.count = bodies;
  out.poses.found = bodies;
  for (int b = 0; b < bodies; ++b) {
    BodyPose& pose = out.poses.bodies[static_cast<std::size_t>(b)];
    pose = BodyPose{};
    pose.found = true;
    pose.T_world_body = h->T_world_body[static_cast<std::size_t>(b)];
    pose.point_index_of_marker.fill(-1);
    const auto& markers = sc.targets.bodies[static_cast<std::size_t>(b)].markers_body;
    pose.markers = static_cast<int>(markers.size());
    for (std::size_t m = 0; m < markers.size(); ++m)
      pose.point_index_of_marker[m] =
          static_cast<std::int16_t>(add_point(pose.T_world_body * markers[m]));
  }
  add_point(Vec3(-700.0, 300.0, 400.0));  // two strays (a glint, a reflection)
  add_point(Vec3(650.0, -200.0, 1700.0));

  auto solver =
      kinematics::JointAngleSolver::create(sc.joints_true, static_cast<std::size_t>(bodies));
  EXPECT_TRUE(solver.ok()) << (solver.ok() ? "" : solver.error().message);
  if (!solver.ok()) return h;
  out.angles = solver->make_output();
  std::vector<kinematics::BodyPoseView> views;
  for (const Iso3& T : h->T_world_body) views.push_back({true, T});
  EXPECT_TRUE(solver->compute(views.data(), out.angles));
  return h;
}

}  // namespace mocap::testing
