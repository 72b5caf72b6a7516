// Design: tests of the temporal path: same identities as the full search on smooth
// motion, fallback on a wrong prior (swapped bodies), rejection of jumps beyond the speed
// limits and re-acquisition on the next frame.
#include <gtest/gtest.h>

#include <cstdio>
#include <random>

#include "identify/identifier.h"
#include "tests/identify/identify_test_util.h"

namespace mocap {
namespace {

using test::make_scene;
using test::random_target;
using test::SceneOptions;

TargetSet three_bodies(std::mt19937_64& rng) {
  for (;;) {
    TargetSet set;
    for (int b = 0; b < 3; ++b)
      set.bodies.push_back(random_target(rng, 5, "b" + std::to_string(b)));
    auto id = Identifier::create(set, IdentifyConfig{});
    if (id.ok() && id->warnings().empty()) return set;
  }
}

Iso3 moving_pose(int body, int frame) {
  const double s = frame * 0.01;  // 100 fps
  Iso3 T = Iso3::Identity();
  T.linear() = (Eigen::AngleAxisd(0.8 * s + body, Vec3::UnitZ()) *
                Eigen::AngleAxisd(0.5 * std::sin(2.0 * s + body), Vec3::UnitX()))
                   .toRotationMatrix();
  T.translation() =
      Vec3(300.0 * body + 100.0 * std::sin(1.3 * s), 80.0 * std::cos(s), 2000.0 + 50.0 * s);
  return T;
}

TEST(Temporal, SameIdentitiesAsFullSearch) {
  std::mt19937_64 rng(51);
  const TargetSet set = three_bodies(rng);
  IdentifyConfig warm_cfg, cold_cfg;
  cold_cfg.temporal = false;
  auto warm = Identifier::create(set, warm_cfg);
  auto cold = Identifier::create(set, cold_cfg);
  ASSERT_TRUE(warm.ok() && cold.ok());
  for (auto model : {MotionModel::kConstantVelocity, MotionModel::kConstantPose}) {
    warm_cfg.motion_model = model;
    warm = Identifier::create(set, warm_cfg);
    int more = 0;
    for (int f = 0; f < test::scaled_trials(500); ++f) {
      std::vector<Iso3> poses;
      for (int b = 0; b < 3; ++b) poses.push_back(moving_pose(b, f));
      SceneOptions opt;
      opt.noise_mm = 0.2;
      opt.strays = 10;
      opt.occlude = (f % 7 == 3);
      const auto scene = make_scene(rng, set, opt, &poses);
      BodyPoses a, b;
      const std::int64_t t_ns = f * 10'000'000LL;
      warm->identify(scene.pts.data(), static_cast<int>(scene.pts.size()), t_ns, a);
      cold->identify(scene.pts.data(), static_cast<int>(scene.pts.size()), t_ns, b);
      for (int i = 0; i < 3; ++i) {
        const auto& pa = a.bodies[static_cast<std::size_t>(i)];
        const auto& pb = b.bodies[static_cast<std::size_t>(i)];
        // The temporal path finds every body the full search finds, with the same
        // points; it may find more (an ambiguous cold solution decided by continuity).
        EXPECT_TRUE(test::identity_correct(scene, i, pa)) << "frame " << f;
        if (!pb.found) {
          more += pa.found ? 1 : 0;
          continue;
        }
        ASSERT_TRUE(pa.found) << "frame " << f;
        EXPECT_EQ(pa.point_index_of_marker, pb.point_index_of_marker) << "frame " << f;
        EXPECT_TRUE(pa.T_world_body.isApprox(pb.T_world_body, 1e-9));
      }
    }
    const auto& c = warm->counters();
    EXPECT_GT(c.warm_accepted, c.frames * 2);  // most bodies by the temporal path
    EXPECT_EQ(c.velocity_rejects, 0u);
    EXPECT_LE(more, static_cast<int>(c.continuity_resolved));
    std::printf("motion model %d: %d bodies found only by continuity (%llu resolved)\n",
                static_cast<int>(model), more,
                static_cast<unsigned long long>(c.continuity_resolved));
  }
}

// Frame 1: bodies at their places; frame 2: the two bodies swap places (the prior of each
// lands on the other's points). No wrong identity, with and without speed limits; with
// limits the jump drops both tracks and the unambiguous cold solutions re-acquire both
// bodies in the same frame.
TEST(Temporal, SwappedBodiesNeverGiveWrongIdentity) {
  std::mt19937_64 rng(61);
  const TargetSet set = three_bodies(rng);
  for (bool limits : {true, false}) {
    IdentifyConfig cfg;
    if (!limits) cfg.max_speed_mm_per_s = cfg.max_angular_speed_deg_per_s = 0.0;
    auto id = Identifier::create(set, cfg);
    ASSERT_TRUE(id.ok());
    std::vector<Iso3> poses{moving_pose(0, 0), moving_pose(1, 0), moving_pose(2, 0)};
    for (int f = 0; f < 6; ++f) {
      if (f == 3) std::swap(poses[0], poses[1]);
      SceneOptions opt;
      opt.noise_mm = 0.2;
      opt.strays = 10;
      const auto scene = make_scene(rng, set, opt, &poses);
      BodyPoses out;
      id->identify(scene.pts.data(), static_cast<int>(scene.pts.size()), f * 10'000'000LL, out);
      for (int b = 0; b < 3; ++b) {
        const auto& p = out.bodies[static_cast<std::size_t>(b)];
        EXPECT_TRUE(test::identity_correct(scene, b, p)) << "frame " << f << " body " << b;
        EXPECT_TRUE(p.found) << "frame " << f << " body " << b;
        if (f == 3 && b < 2) {  // the swapped ones: by the full search
          EXPECT_FALSE(p.from_prior) << "body " << b;
        }
      }
    }
    EXPECT_GE(id->counters().warm_fallbacks, 2u);
    EXPECT_EQ(id->counters().velocity_rejects, limits ? 2u : 0u);
    EXPECT_EQ(id->counters().jump_reboots, limits ? 2u : 0u);
  }
}

// A jump of one body: its track is dropped (counted) and its unambiguous cold solution
// re-acquires it in the same frame ("boot"); the temporal path resumes afterwards.
TEST(Temporal, JumpRebootsInTheSameFrame) {
  std::mt19937_64 rng(71);
  const TargetSet set = three_bodies(rng);
  IdentifyConfig cfg;
  cfg.max_speed_mm_per_s = 2000.0;
  auto id = Identifier::create(set, cfg);
  ASSERT_TRUE(id.ok());
  std::vector<Iso3> poses{moving_pose(0, 0), moving_pose(1, 0), moving_pose(2, 0)};
  bool found[5];
  bool warm[5];
  for (int f = 0; f < 5; ++f) {
    if (f == 2) poses[2].translation() += Vec3(0.0, 300.0, 0.0);  // 30 m/s for one frame
    const auto scene = make_scene(rng, set, SceneOptions{0.1, 5, false, 3, 300.0}, &poses);
    BodyPoses out;
    id->identify(scene.pts.data(), static_cast<int>(scene.pts.size()), f * 10'000'000LL, out);
    found[f] = out.bodies[2].found;
    warm[f] = out.bodies[2].from_prior;
    EXPECT_TRUE(test::identity_correct(scene, 2, out.bodies[2]));
    EXPECT_TRUE(out.bodies[0].found && out.bodies[1].found);
  }
  EXPECT_TRUE(found[0] && found[1] && found[2] && found[3] && found[4]);
  EXPECT_FALSE(warm[2]);  // booted from the full search
  EXPECT_TRUE(warm[4]);   // tracked again
  EXPECT_EQ(id->counters().velocity_rejects, 1u);
  EXPECT_EQ(id->counters().jump_reboots, 1u);
  // A timestamp going backwards drops the priors (counted), identification goes on.
  const auto scene = make_scene(rng, set, SceneOptions{0.1, 5, false, 3, 300.0}, &poses);
  BodyPoses out;
  EXPECT_TRUE(id->identify(scene.pts.data(), static_cast<int>(scene.pts.size()), 0, out));
  EXPECT_EQ(id->counters().bad_timestamps, 1u);
}

// The temporal gate scales with the time since the body was last seen: a body hidden for
// 3 frames that moved more than 3 single-frame gates meanwhile is still taken by its prior
// on return. Derived gate (constant pose, markers up to 300 mm/s): 3 mm per frame plus
// noise, 12 mm + noise after 4 frames. Without stated limits, warm_gate_mm (3 mm) scaled
// by the age (the former behaviour).
TEST(Temporal, GateScalesWithTimeSinceLastSeen) {
  std::mt19937_64 rng(83);
  const TargetSet set = three_bodies(rng);
  TargetSet others;
  others.bodies = {set.bodies[0], set.bodies[1]};
  for (bool stated_limits : {true, false}) {
    IdentifyConfig cfg;
    cfg.motion_model = MotionModel::kConstantPose;
    if (stated_limits) {
      cfg.max_speed_mm_per_s = 300.0;  // the body moves 2.5 mm per frame (250 mm/s)
    } else {
      cfg.max_speed_mm_per_s = cfg.max_angular_speed_deg_per_s = 0.0;
      cfg.warm_gate_mm = 3.0;
    }
    auto id = Identifier::create(set, cfg);
    ASSERT_TRUE(id.ok());
    auto pose = [](int body, int f) {
      Iso3 T = moving_pose(body, 0);
      T.translation() += Vec3(2.5 * f, 0.0, 0.0);
      return T;
    };
    for (int f = 0; f < 7; ++f) {
      const bool hidden = f >= 2 && f <= 4;
      std::vector<Iso3> poses{pose(0, f), pose(1, f), pose(2, f)};
      std::vector<Iso3> two{poses[0], poses[1]};
      const auto scene = hidden
                             ? make_scene(rng, others, SceneOptions{0.05, 0, false, 3, 300.0}, &two)
                             : make_scene(rng, set, SceneOptions{0.05, 0, false, 3, 300.0}, &poses);
      BodyPoses out;
      id->identify(scene.pts.data(), static_cast<int>(scene.pts.size()), f * 10'000'000LL, out);
      EXPECT_EQ(out.bodies[2].found, !hidden) << "frame " << f;
      if (f == 5) {  // 10 mm from where it was last seen, 4 frames ago
        EXPECT_TRUE(out.bodies[2].from_prior) << stated_limits;
        EXPECT_TRUE(test::identity_correct(scene, 2, out.bodies[2]));
      }
    }
    EXPECT_EQ(id->counters().velocity_rejects, 0u);
    EXPECT_EQ(id->counters().warm_fallbacks, 3u) << stated_limits;  // the 3 hidden frames
  }
}

}  // namespace
}  // namespace mocap
