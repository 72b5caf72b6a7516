// Design: tests of the motion model and of identification by continuity (motion.h,
// identifier_temporal.cpp): the screw prediction (exact for a constant twist, the same for
// any choice of target frame), fast limbs (markers at ~2 m/s, swings of ~460 deg/s,
// frames far from the markers) tracked with 0 reboots and 0 wrong identities and 0 heap
// allocations, a true jump still rebooted, and a triangle that fits two placements of its
// target: decided by the track, never without one, never with two placements in the gates.
#include <gtest/gtest.h>

#include <cstdio>
#include <random>

#include "core/units.h"
#include "identify/identifier.h"
#include "identify/motion.h"
#include "tests/identify/identify_test_util.h"
#include "tests/identify/limb_scene.h"
#include "tests/support/alloc_counter.h"

namespace mocap {
namespace {

using test::make_scene;
using test::SceneOptions;

// The tracker's limits (track/frame_processor.h): markers up to 3 m/s, 1440 deg/s.
IdentifyConfig tracker_config() {
  IdentifyConfig c;
  c.max_speed_mm_per_s = 3000.0;
  c.max_angular_speed_deg_per_s = 1440.0;
  return c;
}

TEST(Motion, ScrewPredictionIsExactForAConstantTwistInAnyFrame) {
  std::mt19937_64 rng(5);
  for (int trial = 0; trial < 50; ++trial) {
    // exp/log round trip, small and large angles.
    const Vec3 w = test::random_rotation(rng).col(0) * (trial < 5 ? 1e-7 * trial : 0.06 * trial);
    const Vec3 v = test::random_rotation(rng).col(1) * 300.0;
    Vec3 w2, v2;
    se3_log(se3_exp(w, v), w2, v2);
    EXPECT_LT((w2 - w).norm(), 1e-9);
    EXPECT_LT((v2 - v).norm(), 1e-7);
  }
  // A limb swinging at 8 rad/s about an axis 0.3 m from the world origin, its target frame
  // 1 m from its markers: two poses 10 ms apart predict the third exactly.
  const MotionBounds motion{IdentifyConfig{}};
  for (double offset_mm : {0.0, 1000.0}) {
    Iso3 T_limb_body = Iso3::Identity();
    T_limb_body.translation() = Vec3(offset_mm, -0.5 * offset_mm, 0.2 * offset_mm);
    auto pose = [&](double t) {
      Iso3 T = Iso3::Identity();
      T.translation() = Vec3(300.0, 0.0, 2000.0);
      return T * Eigen::AngleAxisd(8.0 * t, Vec3(1, 2, 3).normalized()) *
             Eigen::Translation3d(150.0, 0.0, 0.0) * T_limb_body;
    };
    MotionTrack tr;
    tr.valid = tr.has_prev = true;
    tr.T_prev = pose(0.0);
    tr.t_prev_ns = 0;
    tr.T_last = pose(0.01);
    tr.t_last_ns = 10'000'000;
    for (std::int64_t t_ns : {20'000'000LL, 40'000'000LL}) {  // next frame, 3 frames ahead
      const Iso3 T = motion.predict(tr, t_ns);
      const Iso3 truth = pose(static_cast<double>(t_ns) * 1e-9);
      const Vec3 marker = T_limb_body.inverse() * Vec3(0.0, 40.0, 0.0);  // on the limb
      EXPECT_LT((T * marker - truth * marker).norm(), 1e-6) << offset_mm << " " << t_ns;
    }
  }
}

// The gate: constant velocity at the tracker's limits, 100 fps, sigma 0.2 mm, poses whose
// noise at the marker is v0: 0.5 * 3000 * 25.1 mm/s^2 * 0.01 s * 0.02 s = 7.5 mm of motion
// plus q * sqrt(4 v0 + v0 + 3 sigma^2) (last pose weighted (1 + r)^2, previous r^2).
TEST(Motion, GateFollowsTheLimitsTheAgeAndTheNoise) {
  const IdentifyConfig cfg = tracker_config();
  const MotionBounds motion{cfg};
  TargetModel model;
  model.k = 1;
  model.min_pair_mm = 100.0;
  MotionTrack tr;
  tr.valid = tr.has_prev = true;
  tr.t_prev_ns = 0;
  tr.t_last_ns = 10'000'000;
  const double v0 = 0.02, s2 = cfg.point_sigma_mm * cfg.point_sigma_mm;
  tr.noise_last.marker_var_mm2[0] = tr.noise_prev.marker_var_mm2[0] = v0;
  const double a = 3000.0 * 1440.0 * kRadPerDeg;
  const double q = motion.quantile();
  EXPECT_NEAR(q, 4.6, 0.1);
  EXPECT_NEAR(motion.acceleration_mm_per_s2(), a, 1e-6);
  std::array<double, kMaxMarkers> g{};
  motion.gates_mm(tr, 20'000'000, model, g);
  EXPECT_NEAR(g[0], 0.5 * a * 0.01 * 0.02 + q * std::sqrt(4 * v0 + v0 + 3 * s2), 1e-9);
  // Seen 3 frames ago: r = 3, and capped at half the smallest marker distance.
  motion.gates_mm(tr, 40'000'000, model, g);
  EXPECT_NEAR(
      g[0], std::min(50.0, 0.5 * a * 0.03 * 0.04 + q * std::sqrt(16 * v0 + 9 * v0 + 3 * s2)), 1e-9);
  // One pose only: constant pose, v_max * age.
  tr.has_prev = false;
  motion.gates_mm(tr, 20'000'000, model, g);
  EXPECT_NEAR(g[0], 30.0 + q * std::sqrt(v0 + 3 * s2), 1e-9);
}

// The noise of a fitted pose: at the fitted markers of a well-spread fit below a single
// point's 3 sigma^2; far from a nearly collinear triangle (its rotation about its line
// barely measured) much larger, so neither the gates nor the speed limits take such a
// pose's far markers at face value.
TEST(Motion, PoseNoiseFollowsTheGeometryOfTheFit) {
  const IdentifyConfig cfg = tracker_config();
  const MotionBounds motion{cfg};
  TargetModel model;
  model.k = 5;
  model.M_body = {Vec3(0, 0, 0), Vec3(60, 0, 0), Vec3(0, 60, 0), Vec3(0, 0, 60), Vec3(120, 0.5, 0)};
  std::array<std::int16_t, kMaxMarkers> all{}, line{};
  all.fill(-1);
  line.fill(-1);
  for (int c = 0; c < 4; ++c) all[static_cast<std::size_t>(c)] = static_cast<std::int16_t>(c);
  line[0] = 0;
  line[1] = 1;
  line[4] = 4;  // three markers within 0.5 mm of a line
  const double s2 = cfg.point_sigma_mm * cfg.point_sigma_mm;
  const PoseNoise good = motion.pose_noise(model, all);
  for (int c = 0; c < 4; ++c) EXPECT_LT(good.marker_var_mm2[static_cast<std::size_t>(c)], 3 * s2);
  const PoseNoise thin = motion.pose_noise(model, line);
  EXPECT_GT(thin.marker_var_mm2[3], 100.0 * good.marker_var_mm2[3]);  // 60 mm off the line
  EXPECT_GT(thin.angle_var_rad2, 100.0 * good.angle_var_rad2);
}

struct TrackStats {
  int found = 0, seen = 0, wrong = 0, warm = 0;
};

// Runs `frames` frames of the limb scene through `id`; counts per body.
TrackStats run_limbs(Identifier& id, const test::LimbScene& limbs, std::mt19937_64& rng, int frames,
                     const SceneOptions& opt, int jump_frame = -1,
                     std::uint64_t* steady_allocations = nullptr) {
  TrackStats s;
  BodyPoses out;
  Vec3 jump = Vec3::Zero();
  for (int f = 0; f < frames; ++f) {
    auto poses = limbs.poses(f * 0.01);
    if (f == jump_frame) jump = Vec3(0.0, 0.0, 150.0);  // 15 m/s for one frame
    poses[0].translation() += jump;
    const auto scene = make_scene(rng, limbs.set, opt, &poses);
    const int n = static_cast<int>(scene.pts.size());
    if (steady_allocations != nullptr && f >= 5) {
      test::AllocationScope scope;
      id.identify(scene.pts.data(), n, f * 10'000'000LL, out);
      *steady_allocations += scope.count();
    } else {
      id.identify(scene.pts.data(), n, f * 10'000'000LL, out);
    }
    for (int b = 0; b < id.body_count(); ++b) {
      const BodyPose& p = out.bodies[static_cast<std::size_t>(b)];
      int visible = 0;
      for (int q : scene.truth[static_cast<std::size_t>(b)]) visible += q >= 0 ? 1 : 0;
      s.seen += visible >= 3 ? 1 : 0;
      if (!p.found) continue;
      ++s.found;
      s.warm += p.from_prior ? 1 : 0;
      if (!test::identity_correct(scene, b, p)) {
        ++s.wrong;
        ADD_FAILURE() << "wrong identity: frame " << f << " body " << b;
      }
    }
  }
  return s;
}

// 15 limbs at up to ~2 m/s and ~460 deg/s, 100 fps, markers randomly hidden down to 3 per
// body, 0.2 mm noise, strays: every body holds its track (0 jumps, 0 wrong identities),
// and the steady state allocates nothing.
TEST(Temporal, FastLimbsHoldTheirTracks) {
  std::mt19937_64 rng(2024);
  const test::LimbScene limbs = test::make_limb_scene(rng, 15);
  const double v = test::fastest_marker_mm_per_s(limbs, 1.5, 0.005);
  EXPECT_GT(v, 1800.0);
  for (const IdentifyConfig& cfg : {tracker_config(), IdentifyConfig{}}) {
    auto id = Identifier::create(limbs.set, cfg);
    ASSERT_TRUE(id.ok()) << id.error().message;
    SceneOptions opt;
    opt.noise_mm = 0.2;
    opt.strays = 10;
    opt.occlude = true;
    std::uint64_t allocations = 0;
    const TrackStats s = run_limbs(*id, limbs, rng, 150, opt, -1, &allocations);
    const auto& c = id->counters();
    std::printf(
        "fastest marker %.0f mm/s: found %d of %d seen, warm %d, wrong %d, reboots %llu, "
        "continuity %llu, ambiguous %llu\n",
        v, s.found, s.seen, s.warm, s.wrong, static_cast<unsigned long long>(c.jump_reboots),
        static_cast<unsigned long long>(c.continuity_resolved),
        static_cast<unsigned long long>(c.ambiguous_rejects));
    EXPECT_EQ(s.wrong, 0);
    EXPECT_EQ(c.jump_reboots, 0u);
    EXPECT_EQ(c.velocity_rejects, 0u);
    EXPECT_GE(s.found, s.seen * 99 / 100);
    EXPECT_GE(s.warm, s.found * 95 / 100);
    EXPECT_GT(c.continuity_resolved, 0u);
    EXPECT_EQ(allocations, 0u);
  }
}

// A body of the same fast scene jumps 150 mm in one frame (15 m/s, a wrong identity or a
// teleport): its track is dropped and it is re-acquired (booted) from the cold solution.
TEST(Temporal, TrueJumpAmongFastLimbsIsRebooted) {
  std::mt19937_64 rng(2025);
  const test::LimbScene limbs = test::make_limb_scene(rng, 15);
  auto id = Identifier::create(limbs.set, tracker_config());
  ASSERT_TRUE(id.ok());
  SceneOptions opt;
  opt.noise_mm = 0.2;
  opt.strays = 5;
  const TrackStats s = run_limbs(*id, limbs, rng, 60, opt, 30);
  EXPECT_EQ(s.wrong, 0);
  EXPECT_EQ(id->counters().velocity_rejects, 1u);
  EXPECT_EQ(id->counters().jump_reboots, 1u);
  EXPECT_EQ(s.found, s.seen);
}

// Random trials while tracking: 21 sequences of 15 fast limbs (new targets each; joints
// 400, 250 or 150 mm apart: the densest as crowded as a humanoid's neighbouring limbs), 10
// strays, markers hidden down to 3 per body, 0.1-0.3 mm noise: 0 wrong identities (the
// temporal path takes 3-marker bodies by continuity, so it must be as safe as the full
// search's ambiguity rule) and 0 jump reboots (a nearly collinear 3-marker pose, whose
// far markers are barely measured, is no jump: motion.h, pose noise).
TEST(Temporal, NoWrongIdentityWhileTrackingFastLimbs) {
  std::mt19937_64 rng(77);
  std::uniform_real_distribution<double> noise(0.1, 0.3);
  IdentifyConfig cfg = tracker_config();
  cfg.point_sigma_mm = 0.3;  // the consistency test set to the largest noise of the trials
  TrackStats all;
  std::uint64_t continuity = 0, reboots = 0;
  for (int seq = 0; seq < 21; ++seq) {
    const test::LimbScene limbs = test::make_limb_scene(rng, 15, 400.0 - 125.0 * (seq % 3));
    auto id = Identifier::create(limbs.set, cfg);
    ASSERT_TRUE(id.ok());
    SceneOptions opt;
    opt.noise_mm = noise(rng);
    opt.strays = 10;
    opt.occlude = true;
    const TrackStats s = run_limbs(*id, limbs, rng, 100, opt);
    all.found += s.found;
    all.seen += s.seen;
    all.wrong += s.wrong;
    continuity += id->counters().continuity_resolved;
    reboots += id->counters().jump_reboots;
  }
  std::printf("tracking trials: %d of %d found, %d wrong, %llu by continuity\n", all.found,
              all.seen, all.wrong, static_cast<unsigned long long>(continuity));
  EXPECT_EQ(all.wrong, 0);
  EXPECT_EQ(reboots, 0u);
  EXPECT_GE(all.found, all.seen * 99 / 100);
}

}  // namespace
}  // namespace mocap
