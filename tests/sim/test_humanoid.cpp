// Humanoid scene tests: the robot the issue describes (15 bodies, 14 joints of the
// stated types in one tree, 4..6 balls per body, about 70 in all, 14 mm), the ring of
// 1280 x 1024 cameras all around it, target-design rules checked by the identifier's
// own ambiguity search (no symmetric target, no copied target), the forward kinematics
// consistent with the true model over every motion, the motions' ranges and speeds
// (explore covers every degree of freedom; the smooth motion's hands reach about
// 2 m/s), and physical occlusion (a ball behind its own limb is hidden from a camera,
// every ball is seen cleanly by some camera).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <set>
#include <string>

#include "core/units.h"
#include "identify/ambiguity.h"
#include "identify/target_model.h"
#include "sim/motion.h"
#include "sim/render.h"
#include "sim/scene_humanoid.h"
#include "sim/simulate.h"

namespace mocap::sim {
namespace {

SimScene humanoid(int cameras = 0) {
  SimOptions o;
  o.scene = SceneKind::kHumanoid;
  o.cameras = cameras;
  auto s = make_scene(o);
  EXPECT_TRUE(s.ok()) << s.error().message;
  return *s;
}

MotionPlan plan_of(const SimScene& s, MotionKind kind, int frames) {
  MotionSpec spec;
  spec.kind = kind;
  spec.frames = frames;
  auto plan = plan_motion(s, spec);
  EXPECT_TRUE(plan.ok()) << plan.error().message;
  return *plan;
}

TEST(SimHumanoid, FifteenBodiesFourteenJointsInOneTree) {
  const SimScene s = humanoid();
  EXPECT_EQ(s.kind, SceneKind::kHumanoid);
  ASSERT_EQ(s.body_count(), kHumanoidBodies);
  ASSERT_EQ(s.joint_count(), kHumanoidJoints);
  const std::set<std::string> expected = {"pelvis",    "torso",   "head",        "upper_arm_l",
                                          "forearm_l", "hand_l",  "upper_arm_r", "forearm_r",
                                          "hand_r",    "thigh_l", "shank_l",     "foot_l",
                                          "thigh_r",   "shank_r", "foot_r"};
  std::set<std::string> names;
  for (const auto& b : s.targets.bodies) {
    names.insert(b.name);
    EXPECT_GE(b.markers_body.size(), 4u) << b.name;
    EXPECT_LE(b.markers_body.size(), 6u) << b.name;
  }
  EXPECT_EQ(names, expected);
  EXPECT_GE(s.marker_count(), 65);
  EXPECT_LE(s.marker_count(), 75);
  EXPECT_DOUBLE_EQ(s.targets.marker_diameter_mm, 14.0);
  // Ball: waist, neck, shoulders, wrists, hips; hinge: elbows, knees, ankles.
  std::map<std::string, JointType> type;
  for (const JointSpec& j : s.joints_true.joints) type[j.name] = j.type;
  for (const char* n :
       {"waist", "neck", "shoulder_l", "shoulder_r", "wrist_l", "wrist_r", "hip_l", "hip_r"})
    EXPECT_EQ(type.at(n), JointType::kBall) << n;
  for (const char* n : {"elbow_l", "elbow_r", "knee_l", "knee_r", "ankle_l", "ankle_r"})
    EXPECT_EQ(type.at(n), JointType::kHinge) << n;
  // A tree: every body but the root is the child of exactly one joint, whose parent is
  // already placed (topological order).
  std::vector<int> parents(static_cast<std::size_t>(s.body_count()), 0);
  std::vector<bool> placed(static_cast<std::size_t>(s.body_count()), false);
  placed[static_cast<std::size_t>(s.root_body)] = true;
  for (std::size_t k = 0; k < s.tree.size(); ++k) {
    const SimJoint& j = s.tree[k];
    EXPECT_TRUE(placed[static_cast<std::size_t>(j.parent)]) << k;
    placed[static_cast<std::size_t>(j.child)] = true;
    ++parents[static_cast<std::size_t>(j.child)];
    EXPECT_EQ(s.joints_true.joints[k].parent_index, j.parent);
    EXPECT_EQ(s.joints_true.joints[k].child_index, j.child);
  }
  for (int b = 0; b < s.body_count(); ++b)
    EXPECT_EQ(parents[static_cast<std::size_t>(b)], b == s.root_body ? 0 : 1) << b;
}

TEST(SimHumanoid, RingOfCamerasAllAroundTheRobot) {
  const SimScene s = humanoid();
  ASSERT_EQ(s.rig.cameras.size(), 8u);
  std::vector<double> azimuths;
  for (const CameraModel& c : s.rig.cameras) {
    EXPECT_EQ(c.width, 1280);
    EXPECT_EQ(c.height, 1024);
    const Vec3 d = c.center_world() - s.robot_center_world;
    EXPECT_NEAR(std::hypot(d.x(), d.y()), 3000.0, 1.0);
    // Aimed at the robot's centre.
    const Vec3 axis = c.R_cam_world.row(2).transpose();
    EXPECT_GT(axis.dot((s.robot_center_world - c.center_world()).normalized()), 0.9999);
    azimuths.push_back(std::atan2(d.x(), -d.y()) / kRadPerDeg);
  }
  std::sort(azimuths.begin(), azimuths.end());
  for (std::size_t k = 1; k < azimuths.size(); ++k)
    EXPECT_NEAR(azimuths[k] - azimuths[k - 1], 45.0, 0.01);
  for (int n = 2; n <= 8; ++n)
    EXPECT_EQ(humanoid(n).rig.cameras.size(), static_cast<std::size_t>(n));
  SimOptions o;
  o.scene = SceneKind::kHumanoid;
  o.cameras = 33;  // the ring takes up to kMaxCameras (test_cameras.cpp: 12)
  EXPECT_FALSE(make_scene(o).ok());
}

// The identifier's own ambiguity search (independent of the layout search) finds no
// symmetric target and no two targets that are copies of each other with 4 markers.
TEST(SimHumanoid, NoSymmetricOrCopiedTargets) {
  const SimScene s = humanoid(2);
  IdentifyConfig config;
  std::vector<TargetModel> models;
  for (const MarkerTarget& t : s.targets.bodies) {
    auto m = make_target_model(t, config, t.name);
    ASSERT_TRUE(m.ok()) << m.error().message;
    models.push_back(*m);
  }
  for (const AmbiguityFinding& f : find_ambiguities(models, config)) {
    EXPECT_NE(f.body_a, f.body_b) << f.message;  // no target fits itself
    EXPECT_LT(f.markers, 4) << f.message;        // only triangles may fit across limbs
  }
}

TEST(SimHumanoid, TrueModelMatchesTheKinematicsOverEveryMotion) {
  const SimScene s = humanoid(2);
  for (MotionKind kind :
       {MotionKind::kSmooth, MotionKind::kPoses, MotionKind::kExplore, MotionKind::kViewpoints}) {
    SCOPED_TRACE(motion_name(kind));
    const MotionPlan plan = plan_of(s, kind, 44);
    SceneState st = make_state(s);
    for (const JointConfig& cfg : plan.configs) {
      apply_config(s, cfg, st);
      for (std::size_t k = 0; k < s.tree.size(); ++k) {
        const JointSpec& j = s.joints_true.joints[k];
        const Iso3& Tp = st.T_world_body[static_cast<std::size_t>(j.parent_index)];
        const Iso3& Tc = st.T_world_body[static_cast<std::size_t>(j.child_index)];
        EXPECT_LT((Tp * j.center_parent - Tc * j.center_child).norm(), 1e-9) << j.name;
        if (j.type != JointType::kHinge) continue;
        EXPECT_LT((Tp.linear() * j.axis_parent - Tc.linear() * j.axis_child).norm(), 1e-12);
        EXPECT_NEAR(joint_angles_rad(j, Tp, Tc)[0], cfg.q_rad[k].x(), 1e-9) << j.name;
      }
    }
  }
}

// Explore drives every degree of freedom through at least 90 % of its range within
// the ranges; the smooth motion stays within them and its fastest hand moves at
// about 2 m/s (fast, but a normal arm motion).
TEST(SimHumanoid, MotionsCoverTheRangesAtHumanSpeeds) {
  const SimScene s = humanoid(2);
  const MotionPlan explore = plan_of(s, MotionKind::kExplore, 300);
  for (std::size_t k = 0; k < s.tree.size(); ++k) {
    const SimJoint& j = s.tree[k];
    for (int i = 0; i < (j.type == JointType::kBall ? 3 : 1); ++i) {
      double lo = 1e9, hi = -1e9;
      for (const JointConfig& c : explore.configs) {
        lo = std::min(lo, c.q_rad[k][i]);
        hi = std::max(hi, c.q_rad[k][i]);
      }
      const double range = j.upper_rad[i] - j.lower_rad[i];
      EXPECT_GE(lo, j.lower_rad[i] - 1e-9) << k;
      EXPECT_LE(hi, j.upper_rad[i] + 1e-9) << k;
      EXPECT_GT(hi - lo, 0.9 * range) << s.joints_true.joints[k].name << " dof " << i;
    }
  }
  const MotionPlan smooth = plan_of(s, MotionKind::kSmooth, 400);
  SceneState a = make_state(s), b = make_state(s);
  double fastest_mm_per_s = 0.0;
  for (std::size_t f = 1; f < smooth.configs.size(); ++f) {
    apply_config(s, smooth.configs[f - 1], a);
    apply_config(s, smooth.configs[f], b);
    for (int m = 0; m < s.marker_count(); ++m) {
      const auto body = static_cast<std::size_t>(s.marker_body[static_cast<std::size_t>(m)]);
      const Vec3 p = s.marker_in_body(m);
      fastest_mm_per_s = std::max(
          fastest_mm_per_s, (b.T_world_body[body] * p - a.T_world_body[body] * p).norm() * 100.0);
    }
  }
  EXPECT_GT(fastest_mm_per_s, 1500.0);
  EXPECT_LT(fastest_mm_per_s, 3500.0);
}

// Occlusion is physical: from every camera some balls are hidden behind their own limb
// (the ray to them passes through the limb's capsule), and at the reference pose every
// ball is seen cleanly (whole) by at least one of the eight cameras and at least half
// visible in two (it can be triangulated).
TEST(SimHumanoid, LimbsHideBallsAndEveryBallIsSeenCleanly) {
  const SimScene s = humanoid();
  auto ws = RenderWorkspace::create(s);
  ASSERT_TRUE(ws.ok()) << ws.error().message;
  SceneState st = make_state(s);
  std::vector<int> clean(static_cast<std::size_t>(s.marker_count()), 0);
  std::vector<int> mostly(static_cast<std::size_t>(s.marker_count()), 0);
  for (int c = 0; c < static_cast<int>(s.rig.cameras.size()); ++c) {
    Image img = make_camera_image(s, c);
    ASSERT_TRUE(render(s, st, c, *ws, img));
    int hidden = 0;
    for (int m = 0; m < s.marker_count(); ++m) {
      const MarkerView& mv = ws->markers[static_cast<std::size_t>(m)];
      if (mv.isolated()) ++clean[static_cast<std::size_t>(m)];
      if (mv.in_front && mv.inside_image && mv.visible_area_px > mv.occluded_area_px)
        ++mostly[static_cast<std::size_t>(m)];
      if (mv.in_front && mv.visible_area_px == 0.0) ++hidden;
    }
    EXPECT_GE(hidden, 10) << "camera " << c;
  }
  for (int m = 0; m < s.marker_count(); ++m) {
    EXPECT_GE(clean[static_cast<std::size_t>(m)], 1) << "marker " << m;
    EXPECT_GE(mostly[static_cast<std::size_t>(m)], 2) << "marker " << m;
  }
}

TEST(SimHumanoid, WritesARecordingWithGroundTruthForEveryBody) {
  SimOptions o;
  o.scene = SceneKind::kHumanoid;
  o.cameras = 3;
  o.frames = 2;
  const std::string dir = ::testing::TempDir() + "/humanoid_rec";
  auto r = write_simulated_recording(o, dir);
  ASSERT_TRUE(r.ok()) << r.error().message;
  EXPECT_EQ(r->cameras, 3);
  EXPECT_EQ(r->marker_views, static_cast<std::int64_t>(3) * 2 * humanoid(3).marker_count());
  EXPECT_GT(r->isolated_views, r->marker_views / 5);
  EXPECT_GT(r->occluded_views, 0);
}

}  // namespace
}  // namespace mocap::sim
