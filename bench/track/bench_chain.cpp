// Design: the cost of kinematic-chain tracking per frame, in one run with its baseline.
//  - baseline: JointAngleSolver::compute, the angle stage as it was before chain tracking
//    (both joints from the two poses), on the same poses;
//  - poses: ChainSolver::solve when every body was found (the chain only adds the
//    standard deviations of the angles);
//  - hinge_1: the lower arm from 1 marker (elbow through the chain, warm start);
//  - ball_2_hinge_1: the upper arm from 2 markers and the lower arm from 1 (shoulder and
//    elbow solved jointly);
//  - cold_ball_3_hinge_2: the same without a prior (labelling search on the loci only).
// The simulator's shoulder rig and true model, 40 extra stray points per frame. Each
// benchmark also reports the p99 of the per-call time (counter p99_us).
#include <benchmark/benchmark.h>

#include <algorithm>
#include <numbers>
#include <random>
#include <vector>

#include "core/clock.h"
#include "core/latency_histogram.h"
#include "core/units.h"
#include "kinematics/joint_angles.h"
#include "sim/scene.h"
#include "track/chain_solver.h"

namespace mocap {
namespace {

struct Case {
  sim::SimScene scene;
  std::vector<MeasuredPoint> pts;
  BodyPoses poses;
  BodyPoses full;  // every body found (the prior)
};

Case make_case(const std::array<std::vector<int>, 3>& visible, const std::array<bool, 3>& found) {
  Case c;
  sim::SceneOptions options;
  options.kind = sim::SceneKind::kStalks;  // the marker indices below are this layout's
  c.scene = sim::build_shoulder_scene(options).value();
  sim::JointConfig jc = sim::make_config(c.scene);
  jc.q_rad[sim::kShoulderJoint] = Vec3(-20, -30, -20) * kRadPerDeg;
  jc.q_rad[sim::kElbowJoint].x() = 30 * kRadPerDeg;
  sim::SceneState st = sim::make_state(c.scene);
  sim::apply_config(c.scene, jc, st);
  std::mt19937 rng(3);
  std::normal_distribution<double> n(0.0, 0.1);
  std::uniform_real_distribution<double> u(-400.0, 400.0);
  c.poses.count = c.full.count = 3;
  for (int b = 0; b < 3; ++b) {
    const auto ub = static_cast<std::size_t>(b);
    c.poses.bodies[ub].point_index_of_marker.fill(-1);
    c.full.bodies[ub].point_index_of_marker.fill(-1);
    const auto& markers = c.scene.targets.bodies[ub].markers_body;
    for (std::size_t m = 0; m < markers.size(); ++m) {
      const bool vis = found[ub] || std::find(visible[ub].begin(), visible[ub].end(),
                                              static_cast<int>(m)) != visible[ub].end();
      if (!vis) continue;
      MeasuredPoint p;
      p.X_world = st.T_world_body[ub] * markers[m] + Vec3(n(rng), n(rng), n(rng));
      p.blob_index = {static_cast<std::int16_t>(c.pts.size()),
                      static_cast<std::int16_t>(c.pts.size())};
      if (found[ub])
        c.poses.bodies[ub].point_index_of_marker[m] = static_cast<std::int16_t>(c.pts.size());
      c.full.bodies[ub].point_index_of_marker[m] = static_cast<std::int16_t>(c.pts.size());
      c.pts.push_back(p);
    }
    c.poses.bodies[ub].found = found[ub];
    c.poses.bodies[ub].T_world_body = st.T_world_body[ub];
    c.full.bodies[ub].found = true;
    c.full.bodies[ub].T_world_body = st.T_world_body[ub];
  }
  for (int s = 0; s < 40; ++s) {
    MeasuredPoint p;
    p.X_world = Vec3(u(rng), u(rng) + 200.0, u(rng));
    p.blob_index = {static_cast<std::int16_t>(c.pts.size()),
                    static_cast<std::int16_t>(c.pts.size())};
    c.pts.push_back(p);
  }
  return c;
}

void report_p99(benchmark::State& state, const LatencyHistogram& rec) {
  state.counters["p99_us"] = rec.percentile_us(0.99);
}

void BM_Baseline_AnglesFromPoses(benchmark::State& state) {
  Case c = make_case({}, {true, true, true});
  auto solver = kinematics::JointAngleSolver::create(c.scene.joints_true, 3).value();
  kinematics::JointAngles out = solver.make_output();
  std::array<kinematics::BodyPoseView, 3> views;
  for (std::size_t b = 0; b < 3; ++b) views[b] = {true, c.poses.bodies[b].T_world_body};
  LatencyHistogram rec;
  for (auto _ : state) {
    const std::int64_t t0 = monotonic_ns();
    solver.compute(views.data(), out);
    rec.record(monotonic_ns() - t0);
    benchmark::DoNotOptimize(out.valid_count);
  }
  report_p99(state, rec);
}

void run_chain(benchmark::State& state, const std::array<std::vector<int>, 3>& visible,
               const std::array<bool, 3>& found, bool warm) {
  Case c = make_case(visible, found);
  auto model = ChainModel::create(c.scene.joints_true, c.scene.targets).value();
  ChainSolver solver = ChainSolver::create(std::move(model), ChainConfig{}).value();
  ChainResult r;
  LatencyHistogram rec;
  std::int64_t t = 1'000'000'000;
  for (auto _ : state) {
    if (warm)
      solver.remember(c.full, t);
    else
      solver.reset();
    t += 10'000'000;
    const std::int64_t t0 = monotonic_ns();
    solver.solve(c.pts.data(), static_cast<int>(c.pts.size()), t, c.poses, r);
    rec.record(monotonic_ns() - t0);
    benchmark::DoNotOptimize(r.joints[0].solved_by);
  }
  if (r.joints[1].solved_by == client::SolvedBy::kNone) state.SkipWithError("elbow not solved");
  report_p99(state, rec);
}

void BM_Chain_AllFound(benchmark::State& s) { run_chain(s, {}, {true, true, true}, true); }
void BM_Chain_Hinge1(benchmark::State& s) {
  run_chain(s, {{{}, {}, {2}}}, {true, true, false}, true);
}
void BM_Chain_Ball2Hinge1(benchmark::State& s) {
  run_chain(s, {{{}, {1, 3}, {2}}}, {true, false, false}, true);
}
void BM_Chain_ColdBall3Hinge2(benchmark::State& s) {
  run_chain(s, {{{}, {0, 2, 4}, {1, 3}}}, {true, false, false}, false);
}

BENCHMARK(BM_Baseline_AnglesFromPoses);
BENCHMARK(BM_Chain_AllFound);
BENCHMARK(BM_Chain_Hinge1);
BENCHMARK(BM_Chain_Ball2Hinge1);
BENCHMARK(BM_Chain_ColdBall3Hinge2);

}  // namespace
}  // namespace mocap

BENCHMARK_MAIN();
