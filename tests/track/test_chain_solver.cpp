// Tests of kinematic-chain tracking (track/chain_solver.h) on the simulator's true model
// with synthetic 3D points: a hinge from 1 marker and a ball from 2 with a prior, cold
// starts, two levels solved jointly, ambiguity, chi-square rejection of a corrupted
// marker, standard deviations that match the observed errors, no allocation per frame.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>

#include "core/rotation.h"
#include "core/units.h"
#include "sim/scene.h"
#include "tests/support/alloc_counter.h"
#include "track/chain_solver.h"

namespace mocap {
namespace {

struct Fixture {
  sim::SimScene scene;
  ChainSolver solver;
  std::mt19937 rng{7};
  double noise_mm = 0.05;

  static Fixture make(const ChainConfig& config = {}) {
    sim::SceneOptions options;
    options.kind = sim::SceneKind::kStalks;  // the marker indices below are this layout's
    auto scene = sim::build_shoulder_scene(options);
    EXPECT_TRUE(scene.ok());
    auto model = ChainModel::create(scene->joints_true, scene->targets);
    EXPECT_TRUE(model.ok()) << model.error().message;
    auto solver = ChainSolver::create(std::move(model).value(), config);
    EXPECT_TRUE(solver.ok()) << solver.error().message;
    return Fixture{std::move(scene).value(), std::move(solver).value()};
  }

  sim::SceneState pose(const Vec3& shoulder_deg, double elbow_deg) const {
    sim::JointConfig jc = sim::make_config(scene);
    jc.q_rad[sim::kShoulderJoint] = shoulder_deg * kRadPerDeg;
    jc.q_rad[sim::kElbowJoint].x() = elbow_deg * kRadPerDeg;
    sim::SceneState st = sim::make_state(scene);
    sim::apply_config(scene, jc, st);
    return st;
  }

  // Points of the visible markers (visible[body] = marker indices), noisy; poses of the
  // bodies in `found` as identification would report them (exact pose, all labels).
  void frame(const sim::SceneState& st, const std::array<std::vector<int>, 3>& visible,
             const std::array<bool, 3>& found, std::vector<MeasuredPoint>& pts, BodyPoses& poses) {
    std::normal_distribution<double> n(0.0, noise_mm);
    pts.clear();
    poses = BodyPoses{};
    poses.count = 3;
    for (int b = 0; b < 3; ++b) {
      BodyPose& bp = poses.bodies[static_cast<std::size_t>(b)];
      bp.point_index_of_marker.fill(-1);
      for (const int m : visible[static_cast<std::size_t>(b)]) {
        MeasuredPoint p;
        p.X_world = st.T_world_body[static_cast<std::size_t>(b)] *
                        scene.targets.bodies[static_cast<std::size_t>(b)]
                            .markers_body[static_cast<std::size_t>(m)] +
                    Vec3(n(rng), n(rng), n(rng));
        p.blob_index = {static_cast<std::int16_t>(pts.size()),
                        static_cast<std::int16_t>(pts.size())};
        if (found[static_cast<std::size_t>(b)])
          bp.point_index_of_marker[static_cast<std::size_t>(m)] =
              static_cast<std::int16_t>(pts.size());
        pts.push_back(p);
      }
      bp.found = found[static_cast<std::size_t>(b)];
      if (bp.found) {
        bp.T_world_body = st.T_world_body[static_cast<std::size_t>(b)];
        ++poses.found;
      }
    }
  }

  // The final poses as FrameProcessor assembles them, then remember().
  void accept(BodyPoses poses, const ChainResult& r, std::int64_t t) {
    for (int b = 0; b < 3; ++b) {
      if (!r.chain_body[static_cast<std::size_t>(b)]) continue;
      poses.bodies[static_cast<std::size_t>(b)].found = true;
      poses.bodies[static_cast<std::size_t>(b)].T_world_body =
          r.T_world_body[static_cast<std::size_t>(b)];
    }
    solver.remember(poses, t);
  }
};

std::vector<int> all_of(const sim::SimScene& s, int b) {
  std::vector<int> v;
  for (std::size_t m = 0; m < s.targets.bodies[static_cast<std::size_t>(b)].markers_body.size();
       ++m)
    v.push_back(static_cast<int>(m));
  return v;
}

double rot_err_deg(const Mat3& A, const Mat3& B) {
  return Eigen::AngleAxisd(A.transpose() * B).angle() / kRadPerDeg;
}

constexpr std::int64_t kDt = 10'000'000;  // 100 fps

TEST(ChainSolver, HingeFromOneMarkerWithPrior) {
  Fixture f = Fixture::make();
  std::vector<MeasuredPoint> pts;
  BodyPoses poses;
  ChainResult r;
  const auto all =
      std::array<std::vector<int>, 3>{all_of(f.scene, 0), all_of(f.scene, 1), all_of(f.scene, 2)};
  auto st = f.pose(Vec3(-20, -30, -20), 30.0);
  f.frame(st, all, {true, true, true}, pts, poses);
  f.solver.solve(pts.data(), static_cast<int>(pts.size()), kDt, poses, r);
  EXPECT_EQ(r.joints[1].solved_by, client::SolvedBy::kPoses);
  EXPECT_GT(r.joints[1].sd_rad[0], 0.0);
  f.accept(poses, r, kDt);
  // Next frame: the elbow moved 2 degrees, one lower-arm marker left.
  st = f.pose(Vec3(-20, -30, -20), 32.0);
  f.frame(st, {all_of(f.scene, 0), all_of(f.scene, 1), {2}}, {true, true, false}, pts, poses);
  f.solver.solve(pts.data(), static_cast<int>(pts.size()), 2 * kDt, poses, r);
  ASSERT_EQ(r.joints[1].solved_by, client::SolvedBy::kChain);
  ASSERT_TRUE(r.chain_body[2]);
  EXPECT_EQ(r.markers[2], 1);
  EXPECT_LT(rot_err_deg(r.T_world_body[2].linear(), st.T_world_body[2].linear()), 0.1);
  EXPECT_GT(r.joints[1].sd_rad[0], 0.0);
  EXPECT_LT(r.joints[1].sd_rad[0], 0.5 * kRadPerDeg);
  // The shoulder still comes from the two poses.
  EXPECT_EQ(r.joints[0].solved_by, client::SolvedBy::kPoses);
}

TEST(ChainSolver, ColdStartNeedsOneMoreMarker) {
  Fixture f = Fixture::make();
  std::vector<MeasuredPoint> pts;
  BodyPoses poses;
  ChainResult r;
  const auto st = f.pose(Vec3(10, -20, 5), 45.0);
  f.frame(st, {all_of(f.scene, 0), all_of(f.scene, 1), {1}}, {true, true, false}, pts, poses);
  f.solver.solve(pts.data(), static_cast<int>(pts.size()), kDt, poses, r);
  EXPECT_EQ(r.joints[1].solved_by, client::SolvedBy::kNone);  // 1 label, no prior
  f.frame(st, {all_of(f.scene, 0), all_of(f.scene, 1), {1, 3}}, {true, true, false}, pts, poses);
  f.solver.solve(pts.data(), static_cast<int>(pts.size()), 2 * kDt, poses, r);
  ASSERT_EQ(r.joints[1].solved_by, client::SolvedBy::kChain);
  EXPECT_LT(rot_err_deg(r.T_world_body[2].linear(), st.T_world_body[2].linear()), 0.1);
  // A ball from 3 cold markers (upper arm lost), the hinge below it jointly from 2.
  f.solver.reset();
  f.frame(st, {all_of(f.scene, 0), {0, 2, 4}, {1, 3}}, {true, false, false}, pts, poses);
  f.solver.solve(pts.data(), static_cast<int>(pts.size()), 3 * kDt, poses, r);
  ASSERT_EQ(r.joints[0].solved_by, client::SolvedBy::kChain);
  ASSERT_EQ(r.joints[1].solved_by, client::SolvedBy::kChain);
  EXPECT_LT(rot_err_deg(r.T_world_body[1].linear(), st.T_world_body[1].linear()), 0.1);
  EXPECT_LT(rot_err_deg(r.T_world_body[2].linear(), st.T_world_body[2].linear()), 0.1);
}

TEST(ChainSolver, BallFromTwoMarkersWithPrior) {
  Fixture f = Fixture::make();
  std::vector<MeasuredPoint> pts;
  BodyPoses poses;
  ChainResult r;
  const auto all =
      std::array<std::vector<int>, 3>{all_of(f.scene, 0), all_of(f.scene, 1), all_of(f.scene, 2)};
  auto st = f.pose(Vec3(-10, 20, 15), 20.0);
  f.frame(st, all, {true, true, true}, pts, poses);
  f.solver.solve(pts.data(), static_cast<int>(pts.size()), kDt, poses, r);
  f.accept(poses, r, kDt);
  st = f.pose(Vec3(-11, 21.5, 14), 21.0);
  f.frame(st, {all_of(f.scene, 0), {1, 3}, all_of(f.scene, 2)}, {true, false, true}, pts, poses);
  f.solver.solve(pts.data(), static_cast<int>(pts.size()), 2 * kDt, poses, r);
  ASSERT_EQ(r.joints[0].solved_by, client::SolvedBy::kChain);
  EXPECT_LT(rot_err_deg(r.T_world_body[1].linear(), st.T_world_body[1].linear()), 0.2);
  // The elbow's child was found, its parent came from the chain: a chain angle too.
  EXPECT_EQ(r.joints[1].solved_by, client::SolvedBy::kChain);
  for (double sd : r.joints[0].sd_rad) EXPECT_GT(sd, 0.0);
}

TEST(ChainSolver, AmbiguousOrCorruptedLabelsAreNotUsed) {
  Fixture f = Fixture::make();
  std::vector<MeasuredPoint> pts;
  BodyPoses poses;
  ChainResult r;
  const auto st = f.pose(Vec3(0, -10, 0), 60.0);
  f.frame(st, {all_of(f.scene, 0), all_of(f.scene, 1), {0, 2}}, {true, true, false}, pts, poses);
  // A stray on marker 0's circle about the elbow axis, 25 degrees further round: marker 0
  // could be either point (the pairwise distance to marker 2 decides only if it differs).
  const auto& spec = f.scene.joints_true.joints[1];
  const Iso3& T_wu = st.T_world_body[1];
  const Vec3 c_w = T_wu * spec.center_parent;
  const Vec3 a_w = T_wu.linear() * spec.axis_parent.normalized();
  const Vec3 m0 = pts[pts.size() - 2].X_world;
  MeasuredPoint stray;
  stray.X_world = c_w + Eigen::AngleAxisd(25.0 * kRadPerDeg, a_w) * (m0 - c_w);
  stray.blob_index = {900, 900};
  pts.push_back(stray);
  f.solver.solve(pts.data(), static_cast<int>(pts.size()), kDt, poses, r);
  if (r.joints[1].solved_by == client::SolvedBy::kChain) {  // only if the stray was excluded
    EXPECT_LT(rot_err_deg(r.T_world_body[2].linear(), st.T_world_body[2].linear()), 0.1);
  }
  EXPECT_NE(r.point_index_of_marker[2][0], static_cast<std::int16_t>(pts.size() - 1));

  // A marker displaced 3 mm along its circle's tangent breaks the pairwise distances:
  // it is never used, and the joint is either solved right from the others or not at all.
  f.solver.reset();
  f.frame(st, {all_of(f.scene, 0), all_of(f.scene, 1), {0, 1, 2}}, {true, true, false}, pts, poses);
  const std::size_t bad = pts.size() - 3;
  pts[bad].X_world = c_w + Eigen::AngleAxisd(3.0 / (pts[bad].X_world - c_w).norm(), a_w) *
                               (pts[bad].X_world - c_w);
  f.solver.solve(pts.data(), static_cast<int>(pts.size()), 2 * kDt, poses, r);
  EXPECT_NE(r.point_index_of_marker[2][0], static_cast<std::int16_t>(bad));
  if (r.joints[1].solved_by == client::SolvedBy::kChain) {
    EXPECT_LT(rot_err_deg(r.T_world_body[2].linear(), st.T_world_body[2].linear()), 0.1);
  }

  // All three child points shifted 1.5 mm along the axis: each stays within its locus
  // gate and the pairwise distances hold, so they are labelled; the residual (about
  // 3.6 sigma per marker) fails the chi-square test at 0.99, markers are dropped and, too
  // few left for a cold start, the elbow is not published. (At the default 0.9999 the
  // last two pass: an axial offset leaves the hinge angle itself unbiased.)
  ChainConfig strict;
  strict.confidence = 0.99;
  f = Fixture::make(strict);
  f.frame(st, {all_of(f.scene, 0), all_of(f.scene, 1), {0, 1, 2}}, {true, true, false}, pts, poses);
  for (std::size_t i = pts.size() - 3; i < pts.size(); ++i) pts[i].X_world += 1.5 * a_w;
  const std::uint64_t drops = f.solver.counters().chi2_drops;
  f.solver.solve(pts.data(), static_cast<int>(pts.size()), 3 * kDt, poses, r);
  EXPECT_EQ(r.joints[1].solved_by, client::SolvedBy::kNone);
  EXPECT_GT(f.solver.counters().chi2_drops, drops);
  EXPECT_FALSE(r.chain_body[2]);
}

TEST(ChainSolver, StandardDeviationMatchesObservedError) {
  // Property: over random poses and marker subsets, the chain's elbow angle error divided
  // by its stated sd has an RMS near 1 (0.5-2), and no error exceeds 5 sd.
  Fixture f = Fixture::make();
  f.noise_mm = 0.2;
  std::vector<MeasuredPoint> pts;
  BodyPoses poses;
  ChainResult r;
  std::uniform_real_distribution<double> u(-30.0, 30.0);
  double sum_z2 = 0.0;
  int n = 0;
  for (int trial = 0; trial < 200; ++trial) {
    const Vec3 sh(u(f.rng), u(f.rng), u(f.rng));
    const double el = 45.0 + u(f.rng);
    const auto st = f.pose(sh, el);
    const int m = static_cast<int>(f.rng() % 4);
    f.frame(st, {all_of(f.scene, 0), all_of(f.scene, 1), {m, (m + 2) % 4}}, {true, true, false},
            pts, poses);
    f.solver.reset();
    f.solver.solve(pts.data(), static_cast<int>(pts.size()), (trial + 1) * kDt, poses, r);
    if (r.joints[1].solved_by != client::SolvedBy::kChain) continue;
    const double err =
        rot_err_deg(r.T_world_body[2].linear(), st.T_world_body[2].linear()) * kRadPerDeg;
    const double z = err / r.joints[1].sd_rad[0];
    EXPECT_LT(z, 5.0) << "trial " << trial;
    sum_z2 += z * z;
    ++n;
  }
  ASSERT_GT(n, 150);
  const double rms_z = std::sqrt(sum_z2 / n);
  EXPECT_GT(rms_z, 0.4);
  EXPECT_LT(rms_z, 2.0);
}

TEST(ChainSolver, SteadyStateAllocatesNothing) {
  Fixture f = Fixture::make();
  std::vector<MeasuredPoint> pts;
  pts.reserve(64);
  BodyPoses poses;
  ChainResult r;
  const auto all =
      std::array<std::vector<int>, 3>{all_of(f.scene, 0), all_of(f.scene, 1), all_of(f.scene, 2)};
  auto st = f.pose(Vec3(-20, -30, -20), 30.0);
  f.frame(st, all, {true, true, true}, pts, poses);
  f.solver.solve(pts.data(), static_cast<int>(pts.size()), kDt, poses, r);
  f.accept(poses, r, kDt);
  f.frame(st, {all_of(f.scene, 0), {0, 1}, {2}}, {true, false, false}, pts, poses);
  test::AllocationScope scope;
  for (int i = 2; i < 50; ++i) {
    f.solver.solve(pts.data(), static_cast<int>(pts.size()), i * kDt, poses, r);
    f.accept(poses, r, i * kDt);
  }
  EXPECT_EQ(scope.count(), 0u);
  EXPECT_EQ(r.joints[0].solved_by, client::SolvedBy::kChain);
}

}  // namespace
}  // namespace mocap
