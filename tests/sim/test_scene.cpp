// Scene tests: the rig is the paper's, the targets of both marker layouts are
// distinguishable (distinct inter-marker distances, non-congruent targets, nothing for
// the identifier's ambiguity check), the limbs layout surrounds each limb, the true
// joint model is consistent with the forward kinematics, the joint angles follow the
// documented conventions, and the arm stays in both images over the motions.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>

#include "core/rotation.h"
#include "core/units.h"
#include "identify/ambiguity.h"
#include "identify/target_model.h"
#include "sim/motion.h"
#include "sim/simulate.h"

namespace mocap::sim {
namespace {

SimScene default_scene() {
  auto s = make_scene(SimOptions{});
  EXPECT_TRUE(s.ok());
  return *s;
}

SimScene scene_of(SceneKind kind) {
  SimOptions o;
  o.scene = kind;
  auto s = make_scene(o);
  EXPECT_TRUE(s.ok()) << s.error().message;
  return *s;
}

constexpr SceneKind kScenes[] = {SceneKind::kLimbs, SceneKind::kStalks};

// Both scenes: the paper's pair (1032 x 776, f ~ 1290 px, 477 mm baseline, verged). The
// stalks pair stands at the robot's height about 1 m away; the limbs pair is mounted as a
// lab mounts it, about 1.5 m away and looking down at the robot.
TEST(SimScene, StereoRigLikeThePaper) {
  for (SceneKind kind : kScenes) {
    SCOPED_TRACE(scene_name(kind));
    const SimScene s = scene_of(kind);
    ASSERT_EQ(s.rig.cameras.size(), 2u);
    const CameraModel& c0 = s.rig.cameras[0];
    const CameraModel& c1 = s.rig.cameras[1];
    EXPECT_EQ(c0.width, 1032);
    EXPECT_EQ(c0.height, 776);
    EXPECT_NEAR((c0.center_world() - c1.center_world()).norm(), 477.0, 0.5);
    EXPECT_NEAR(c0.fx, 1290.0, 5.0);
    const Vec3 mid = 0.5 * (c0.center_world() + c1.center_world());
    const double dist = (s.robot_center_world - mid).norm();
    const Vec3 z0 = c0.R_cam_world.row(2).transpose(), z1 = c1.R_cam_world.row(2).transpose();
    const double down_deg = std::asin(-(z0 + z1).normalized().z()) / kRadPerDeg;
    if (kind == SceneKind::kStalks) {
      EXPECT_GT(dist, 900.0);
      EXPECT_LT(dist, 1150.0);
      EXPECT_LT(std::abs(down_deg), 5.0);
    } else {
      EXPECT_GT(dist, 1300.0);
      EXPECT_LT(dist, 1700.0);
      EXPECT_GT(down_deg, 25.0);
      EXPECT_LT(down_deg, 45.0);
    }
    // Verged: the optical axes converge.
    EXPECT_GT(std::acos(z0.dot(z1)) / kRadPerDeg, 10.0);
    EXPECT_LT(std::acos(z0.dot(z1)) / kRadPerDeg, 40.0);
  }
}

TEST(SimScene, DefaultIsTheLimbsLayoutAndNamesParse) {
  EXPECT_EQ(default_scene().kind, SceneKind::kLimbs);
  EXPECT_EQ(*parse_scene("limbs"), SceneKind::kLimbs);
  EXPECT_EQ(*parse_scene("stalks"), SceneKind::kStalks);
  EXPECT_EQ(*parse_scene("humanoid"), SceneKind::kHumanoid);
  const auto bad = parse_scene("arms");
  ASSERT_FALSE(bad.ok());
  EXPECT_EQ(bad.error().message, "simulate: scene: unknown scene 'arms' (limbs|stalks|humanoid)");
}

TEST(SimScene, IdentifierFindsNoAmbiguityInEitherLayout) {
  for (SceneKind kind : kScenes) {
    const SimScene s = scene_of(kind);
    IdentifyConfig config;  // the defaults of `mocap track` and `mocap run` (t = 5 mm)
    std::vector<TargetModel> models;
    for (const MarkerTarget& t : s.targets.bodies) {
      auto m = make_target_model(t, config, t.name);
      ASSERT_TRUE(m.ok()) << m.error().message;
      models.push_back(*m);
    }
    const auto findings = find_ambiguities(models, config);
    for (const auto& f : findings) ADD_FAILURE() << scene_name(kind) << ": " << f.message;
    if (kind == SceneKind::kStalks) continue;  // built for t = 5 mm
    // Also with a looser t: the limbs layout keeps a margin over the default.
    config.t_mm = 6.0;
    models.clear();
    for (const MarkerTarget& t : s.targets.bodies)
      models.push_back(*make_target_model(t, config, t.name));
    EXPECT_TRUE(find_ambiguities(models, config).empty()) << scene_name(kind);
  }
}

// The limbs layout: 4..6 balls per body on short bases (ball surface at most 5 mm above
// the limb surface), spread along the limb. Around each arm: at least 3 within 70 deg of
// the side facing the cameras, at least one on the far side (over 100 deg off), and
// azimuths spanning at least 180 deg. The torso, which stands still in front of the
// cameras, carries all of its balls on its front (within 70 deg), over at least 90 deg.
TEST(SimScene, LimbsLayoutSurroundsEachLimbOnShortBases) {
  const MarkerLayout& layout = marker_layout(SceneKind::kLimbs);
  EXPECT_LE(layout.post_radius_mm, 2.0);
  for (std::size_t b = 0; b < layout.mounts.size(); ++b) {
    SCOPED_TRACE(b);
    const auto& mounts = layout.mounts[b];
    const bool torso = b == 0;
    ASSERT_GE(mounts.size(), 4u);
    ASSERT_LE(mounts.size(), 6u);
    std::vector<double> phi, z;
    int front = 0, back = 0;
    for (const MarkerMount& m : mounts) {
      const double p = std::remainder(m.phi_deg, 360.0);
      phi.push_back(p);
      z.push_back(m.z_mm);
      front += std::abs(p) <= 70.0 ? 1 : 0;
      back += std::abs(p) > 100.0 ? 1 : 0;
      EXPECT_GE(m.gap_mm, 2.0);
      EXPECT_LE(m.gap_mm, 5.0);
    }
    std::sort(phi.begin(), phi.end());
    std::sort(z.begin(), z.end());
    if (torso) {
      EXPECT_EQ(front, static_cast<int>(mounts.size()));
      EXPECT_GE(phi.back() - phi.front(), 90.0);
    } else {
      EXPECT_GE(front, 3);
      EXPECT_GE(back, 1);
      EXPECT_GE(phi.back() - phi.front(), 180.0);
    }
    EXPECT_GE(z.back() - z.front(), 120.0);  // spread along the limb
    if (!torso) {  // along an arm; the torso's balls also spread sideways
      for (std::size_t i = 1; i < z.size(); ++i) EXPECT_GE(z[i] - z[i - 1], 20.0);
    }
  }
  const MarkerLayout& stalks = marker_layout(SceneKind::kStalks);
  EXPECT_EQ(stalks.mounts[0].size() + stalks.mounts[1].size() + stalks.mounts[2].size(), 14u);
}

TEST(SimScene, TargetsHaveDistinctDistancesAndAreNotCongruent) {
  for (SceneKind kind : kScenes) {
    SCOPED_TRACE(scene_name(kind));
    const SimScene s = scene_of(kind);
    ASSERT_EQ(s.targets.bodies.size(), 3u);
    std::vector<std::vector<double>> dists;
    for (const MarkerTarget& t : s.targets.bodies) {
      EXPECT_GE(t.markers_body.size(), 4u);
      EXPECT_LE(t.markers_body.size(), 6u);
      std::vector<double> d;
      for (std::size_t i = 0; i < t.markers_body.size(); ++i)
        for (std::size_t j = i + 1; j < t.markers_body.size(); ++j)
          d.push_back((t.markers_body[i] - t.markers_body[j]).norm());
      std::sort(d.begin(), d.end());
      EXPECT_GT(d.front(), 20.0) << t.name;  // balls well apart
      for (std::size_t k = 1; k < d.size(); ++k)
        EXPECT_GT(d[k] - d[k - 1], 2.0) << t.name << " distance " << d[k];
      dists.push_back(d);
    }
    // Non-congruent: no triangle of one target matches a triangle of another within 2 mm.
    auto triangles = [&](const MarkerTarget& t) {
      std::vector<std::array<double, 3>> out;
      const auto& m = t.markers_body;
      for (std::size_t i = 0; i < m.size(); ++i)
        for (std::size_t j = i + 1; j < m.size(); ++j)
          for (std::size_t k = j + 1; k < m.size(); ++k) {
            std::array<double, 3> e = {(m[i] - m[j]).norm(), (m[j] - m[k]).norm(),
                                       (m[i] - m[k]).norm()};
            std::sort(e.begin(), e.end());
            out.push_back(e);
          }
      return out;
    };
    for (std::size_t a = 0; a < 3; ++a)
      for (std::size_t b = a + 1; b < 3; ++b)
        for (const auto& ta : triangles(s.targets.bodies[a]))
          for (const auto& tb : triangles(s.targets.bodies[b])) {
            const double diff = std::max(
                {std::abs(ta[0] - tb[0]), std::abs(ta[1] - tb[1]), std::abs(ta[2] - tb[2])});
            EXPECT_GT(diff, 2.0) << s.targets.bodies[a].name << " vs " << s.targets.bodies[b].name;
          }
  }
}

TEST(SimScene, TrueModelIsConsistentWithTheKinematics) {
  const SimScene s = default_scene();
  MotionSpec spec;
  spec.frames = 60;
  auto plan = plan_motion(s, spec);
  ASSERT_TRUE(plan.ok());
  SceneState st = make_state(s);
  const JointSpec& sh = s.joints_true.joints[0];
  const JointSpec& el = s.joints_true.joints[1];
  for (const JointConfig& cfg : plan->configs) {
    apply_config(s, cfg, st);
    const auto& T = st.T_world_body;
    EXPECT_LT((T[kTorso] * sh.center_parent - T[kUpperArm] * sh.center_child).norm(), 1e-9);
    EXPECT_LT((T[kUpperArm] * el.center_parent - T[kLowerArm] * el.center_child).norm(), 1e-9);
    EXPECT_LT(
        (T[kUpperArm].linear() * el.axis_parent - T[kLowerArm].linear() * el.axis_child).norm(),
        1e-12);
    // Angles: hinge = the commanded elbow angle; ball = Euler XYZ of R_parent^T R_child.
    EXPECT_NEAR(joint_angles_rad(el, T[kUpperArm], T[kLowerArm])[0], cfg.q_rad[kElbowJoint].x(), 1e-9);
    const Vec3 a = joint_angles_rad(sh, T[kTorso], T[kUpperArm]);
    const Mat3 R_rel = T[kTorso].linear().transpose() * T[kUpperArm].linear();
    EXPECT_LT((euler_xyz_to_rotation(a) - R_rel).norm(), 1e-9);
  }
}

TEST(SimScene, HingeAngleSignFollowsTheRightHandRule) {
  const SimScene s = default_scene();
  SceneState st = make_state(s);
  JointConfig cfg = make_config(s);
  cfg.q_rad[kElbowJoint].x() = 0.5;
  apply_config(s, cfg, st);
  // Forearm tip moves towards the cameras (-Y) for a positive angle about axis (-X).
  const Vec3 tip_body = s.T_world_body_ref[kLowerArm].inverse() * Vec3(-60.0, 40.0, -235.0);
  EXPECT_LT((st.T_world_body[kLowerArm] * tip_body).y(), 40.0 - 50.0);
  EXPECT_NEAR(joint_angles_rad(s.joints_true.joints[1], st.T_world_body[kUpperArm],
                               st.T_world_body[kLowerArm])[0],
              0.5, 1e-12);
}

TEST(SimScene, ArmStaysInBothImages) {
  for (SceneKind scene_kind : kScenes) {
    const SimScene s = scene_of(scene_kind);
    for (MotionKind kind :
         {MotionKind::kSmooth, MotionKind::kPoses, MotionKind::kMove400, MotionKind::kViewpoints}) {
      MotionSpec spec;
      spec.kind = kind;
      spec.frames = 220;
      auto plan = plan_motion(s, spec);
      ASSERT_TRUE(plan.ok());
      SceneState st = make_state(s);
      int inside = 0, total = 0;
      for (const JointConfig& cfg : plan->configs) {
        apply_config(s, cfg, st);
        for (int m = 0; m < s.marker_count(); ++m) {
          const Vec3 X = st.T_world_body[static_cast<std::size_t>(
                             s.marker_body[static_cast<std::size_t>(m)])] *
                         s.marker_in_body(m);
          for (const CameraModel& cam : s.rig.cameras) {
            Vec2 px;
            ++total;
            if (project(cam, X, px) && px.x() > 10 && px.y() > 10 && px.x() < cam.width - 11 &&
                px.y() < cam.height - 11)
              ++inside;
            else if (total - inside <= 3)
              std::printf(
                  "  %s %s: %s marker %d at (%.1f, %.1f) in %s\n", scene_name(scene_kind),
                  motion_name(kind),
                  s.targets
                      .bodies[static_cast<std::size_t>(s.marker_body[static_cast<std::size_t>(m)])]
                      .name.c_str(),
                  s.marker_index[static_cast<std::size_t>(m)], px.x(), px.y(), cam.name.c_str());
          }
        }
      }
      const double frac = static_cast<double>(inside) / total;
      std::printf("motion %s: %.2f%% of marker projections inside both images\n", motion_name(kind),
                  100.0 * frac);
      EXPECT_EQ(inside, total) << motion_name(kind) << " " << scene_name(scene_kind);
    }
  }
}

TEST(SimMotion, Move400MovesExactly400mmBetweenHolds) {
  const SimScene s = default_scene();
  MotionSpec spec;
  spec.kind = MotionKind::kMove400;
  spec.frames = 200;
  auto plan = plan_motion(s, spec);
  ASSERT_TRUE(plan.ok());
  int holds = 0;
  for (std::size_t i = 0; i + 2 < plan->segments.size(); i += 3) {
    const MotionSegment& a = plan->segments[i];
    const MotionSegment& b = plan->segments[i + 2];
    ASSERT_EQ(a.kind, "hold");
    ASSERT_EQ(b.kind, "hold");
    const Vec3 ta =
        plan->configs[static_cast<std::size_t>(a.last_frame)].T_world_robot.translation();
    const Vec3 tb =
        plan->configs[static_cast<std::size_t>(b.first_frame)].T_world_robot.translation();
    EXPECT_NEAR((tb - ta).norm(), 400.0, 1e-9);
    EXPECT_EQ(plan->configs[static_cast<std::size_t>(a.first_frame)].T_world_robot.translation(),
              ta);
    ++holds;
  }
  EXPECT_EQ(holds, 4);
}

TEST(SimMotion, PosesAreDistinctAndHeld) {
  const SimScene s = default_scene();
  MotionSpec spec;
  spec.kind = MotionKind::kPoses;
  spec.frames = 110;
  auto plan = plan_motion(s, spec);
  ASSERT_TRUE(plan.ok());
  ASSERT_EQ(plan->segments.size(), 22u);
  for (std::size_t i = 0; i < plan->segments.size(); ++i) {
    const MotionSegment& seg = plan->segments[i];
    EXPECT_EQ(seg.last_frame - seg.first_frame + 1, 5);
    for (std::size_t j = 0; j < i; ++j) {
      const auto& a = plan->configs[static_cast<std::size_t>(seg.first_frame)];
      const auto& b = plan->configs[static_cast<std::size_t>(plan->segments[j].first_frame)];
      EXPECT_GT((a.q_rad[kShoulderJoint] - b.q_rad[kShoulderJoint]).norm() +
                    std::abs(a.q_rad[kElbowJoint].x() - b.q_rad[kElbowJoint].x()),
                5.0 * kRadPerDeg);
    }
  }
  spec.frames = 10;
  EXPECT_FALSE(plan_motion(s, spec).ok());
}

TEST(SimMotion, TimestampsFollowTheFrameRate) {
  EXPECT_EQ(frame_timestamp_ns(0, 100.0), 0);
  EXPECT_EQ(frame_timestamp_ns(3, 100.0), 30000000);
  EXPECT_EQ(frame_timestamp_ns(1, 30.0), 33333333);
}

}  // namespace
}  // namespace mocap::sim
