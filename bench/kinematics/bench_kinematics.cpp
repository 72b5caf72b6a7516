// Design: Google Benchmark of the kinematics module on the synthetic chain of the tests
// (torso -> ball -> upper_arm -> hinge -> lower_arm, 5 markers per body, 0.15 mm noise).
// Baselines measured in the same run: the linear ball solve by normal equations (the
// textbook shortcut our SVD replaces) and Euler angles by Eigen's eulerAngles(0, 1, 2).
#include <benchmark/benchmark.h>

#include <Eigen/Cholesky>

#include "kinematics/calibrate.h"
#include "kinematics/joint_angles.h"
#include "kinematics/linear_estimation.h"
#include "tests/kinematics/synthetic_chain.h"

namespace mocap::kinematics {
namespace {

testing::SyntheticChain chain(int poses) {
  testing::SyntheticOptions o;
  o.poses = poses;
  return testing::make_chain(o);
}

std::vector<RelativePose> relative(const testing::SyntheticChain& c, int p, int ch) {
  std::vector<RelativePose> out;
  for (const auto& f : c.input.frames) {
    out.push_back(relative_pose(f.bodies[static_cast<std::size_t>(p)].T_world_body,
                                f.bodies[static_cast<std::size_t>(ch)].T_world_body));
  }
  return out;
}

void BM_LinearBall(benchmark::State& state) {
  const auto c = chain(static_cast<int>(state.range(0)));
  const auto rel = relative(c, 0, 1);
  for (auto _ : state) {
    auto est = estimate_ball(rel, {}, "bench");
    benchmark::DoNotOptimize(est);
  }
}
BENCHMARK(BM_LinearBall)->Arg(22)->Arg(200)->Unit(benchmark::kMicrosecond);

// Baseline: (M^T M) x = M^T t by Cholesky (squares the condition number, no diagnostics).
void BM_LinearBallNormalEquationsBaseline(benchmark::State& state) {
  const auto c = chain(static_cast<int>(state.range(0)));
  const auto rel = relative(c, 0, 1);
  for (auto _ : state) {
    Eigen::Matrix<double, 6, 6> A = Eigen::Matrix<double, 6, 6>::Zero();
    Eigen::Matrix<double, 6, 1> b = Eigen::Matrix<double, 6, 1>::Zero();
    for (const auto& p : rel) {
      Eigen::Matrix<double, 3, 6> M;
      M << Mat3::Identity(), -p.R_parent_child;
      A += M.transpose() * M;
      b += M.transpose() * p.t_parent_child;
    }
    Eigen::Matrix<double, 6, 1> x = A.ldlt().solve(b);
    benchmark::DoNotOptimize(x);
  }
}
BENCHMARK(BM_LinearBallNormalEquationsBaseline)->Arg(22)->Arg(200)->Unit(benchmark::kMicrosecond);

void BM_LinearHinge(benchmark::State& state) {
  const auto c = chain(static_cast<int>(state.range(0)));
  const auto rel = relative(c, 1, 2);
  for (auto _ : state) {
    auto est = estimate_hinge(rel, {}, "bench");
    benchmark::DoNotOptimize(est);
  }
}
BENCHMARK(BM_LinearHinge)->Arg(22)->Arg(200)->Unit(benchmark::kMicrosecond);

// Whole calibration: linear estimates + Ceres refinement (+ covariance when range(1)).
void BM_Calibrate(benchmark::State& state) {
  const auto c = chain(static_cast<int>(state.range(0)));
  CalibrationOptions opt;
  opt.covariance = state.range(1) != 0;
  for (auto _ : state) {
    auto res = calibrate_joints(c.targets, c.topology, c.input, opt);
    if (!res.ok()) state.SkipWithError(res.error().message.c_str());
    benchmark::DoNotOptimize(res);
  }
}
BENCHMARK(BM_Calibrate)
    ->Args({22, 0})
    ->Args({22, 1})
    ->Args({200, 0})
    ->Args({200, 1})
    ->Unit(benchmark::kMillisecond);

std::vector<std::array<BodyPoseView, 3>> pose_views(const testing::SyntheticChain& c) {
  std::vector<std::array<BodyPoseView, 3>> v;
  for (const auto& f : c.input.frames) {
    v.push_back({{{true, f.bodies[0].T_world_body},
                  {true, f.bodies[1].T_world_body},
                  {true, f.bodies[2].T_world_body}}});
  }
  return v;
}

void BM_JointAnglesPerFrame(benchmark::State& state) {
  const auto c = chain(200);
  auto solver = JointAngleSolver::create(c.truth, 3);
  JointAngles out = solver->make_output();
  const auto views = pose_views(c);
  std::size_t i = 0;
  for (auto _ : state) {
    solver->compute(views[i].data(), out);
    benchmark::DoNotOptimize(out.joints.data());
    i = (i + 1) % views.size();
  }
}
BENCHMARK(BM_JointAnglesPerFrame);

// Baseline: the same two joints with Eigen's generic eulerAngles() and Quaterniond.
void BM_JointAnglesEigenBaseline(benchmark::State& state) {
  const auto c = chain(200);
  const auto views = pose_views(c);
  std::size_t i = 0;
  for (auto _ : state) {
    const auto& v = views[i];
    for (int j = 0; j < 2; ++j) {
      const Mat3 R = v[static_cast<std::size_t>(j)].T_world_body.linear().transpose() *
                     v[static_cast<std::size_t>(j + 1)].T_world_body.linear();
      Vec3 e = R.eulerAngles(0, 1, 2);
      Quat q(R);
      benchmark::DoNotOptimize(e);
      benchmark::DoNotOptimize(q);
    }
    i = (i + 1) % views.size();
  }
}
BENCHMARK(BM_JointAnglesEigenBaseline);

}  // namespace
}  // namespace mocap::kinematics

BENCHMARK_MAIN();
