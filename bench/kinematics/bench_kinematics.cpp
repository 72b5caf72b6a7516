// Design: Google Benchmark of the kinematics module on the synthetic chain of the tests
// (torso -> ball -> upper_arm -> hinge -> lower_arm, 5 markers per body, 0.15 mm noise).
// Baselines measured in the same run: the linear ball solve by normal equations (the
// textbook shortcut our SVD replaces) and Euler angles by Eigen's eulerAngles(0, 1, 2).
// The joint-rate filter on the humanoid's 14 joints (8 ball, 6 hinge: 30 filters) against
// a two-point finite difference of the same angles (the cheapest rate there is), with the
// p50/p99 of one frame's update as counters.
#include <benchmark/benchmark.h>

#include <Eigen/Cholesky>
#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <vector>

#include "kinematics/calibrate.h"
#include "kinematics/joint_angles.h"
#include "kinematics/joint_rates.h"
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

// The humanoid's joints: waist, neck, shoulders, wrists, hips (ball), elbows, knees, ankles.
std::vector<JointType> humanoid_joint_types() {
  std::vector<JointType> t(14, JointType::kBall);
  for (std::size_t j = 8; j < t.size(); ++j) t[j] = JointType::kHinge;
  return t;
}

// Frame k of a smooth motion of every joint, with the stated sd the tracker gives.
void humanoid_frame(int k, JointAngles& a) {
  for (std::size_t j = 0; j < a.joints.size(); ++j) {
    JointAngle& ja = a.joints[j];
    const double t = 0.01 * k, f = 0.25 + 0.03 * static_cast<double>(j);
    ja.valid = (k + static_cast<int>(j)) % 97 != 0;  // now and then a joint is lost
    ja.a0 = 1.2 * std::sin(6.283 * f * t);
    ja.a1 = 0.6 * std::sin(6.283 * 1.3 * f * t + 1.0);
    ja.a2 = 0.4 * std::sin(6.283 * 0.7 * f * t + 2.0);
    ja.sd_rad = {0.002, 0.002, 0.003};
  }
}

template <typename Update>
void run_rates(benchmark::State& state, Update update) {
  const std::vector<JointType> types = humanoid_joint_types();
  JointAngles a;
  a.joints.resize(types.size());
  for (std::size_t j = 0; j < types.size(); ++j) a.joints[j].type = types[j];
  constexpr int kFrames = 1000;  // 10 s at 100 fps, replayed
  std::vector<JointAngles> frames(kFrames, a);
  for (int k = 0; k < kFrames; ++k) humanoid_frame(k, frames[static_cast<std::size_t>(k)]);
  std::vector<double> us;
  us.reserve(1 << 16);
  std::int64_t k = 0;
  for (auto _ : state) {
    JointAngles& f = frames[static_cast<std::size_t>(k % kFrames)];
    const auto t0 = std::chrono::steady_clock::now();
    update(k * 10'000'000, f);
    const auto t1 = std::chrono::steady_clock::now();
    benchmark::DoNotOptimize(f.joints.data());
    if (us.size() < us.capacity())
      us.push_back(std::chrono::duration<double, std::micro>(t1 - t0).count());
    ++k;
  }
  std::sort(us.begin(), us.end());
  if (!us.empty()) {
    state.counters["p50_us"] = us[us.size() / 2];
    state.counters["p99_us"] = us[us.size() * 99 / 100];
  }
}

void BM_JointRateFilterHumanoid(benchmark::State& state) {
  auto filter = JointRateFilter::create({}, humanoid_joint_types());
  run_rates(state, [&](std::int64_t t_ns, JointAngles& a) { filter->update(t_ns, a); });
}
BENCHMARK(BM_JointRateFilterHumanoid);

// Baseline: (a_k - a_{k-1}) / dt per degree of freedom, no noise model, no sd.
void BM_JointRateFiniteDifferenceBaseline(benchmark::State& state) {
  std::vector<std::array<double, 3>> last(14);
  std::vector<std::int64_t> last_t(14, -1);
  run_rates(state, [&](std::int64_t t_ns, JointAngles& a) {
    for (std::size_t j = 0; j < a.joints.size(); ++j) {
      JointAngle& ja = a.joints[j];
      if (!ja.valid) continue;
      const std::array<double, 3> now{ja.a0, ja.a1, ja.a2};
      if (last_t[j] >= 0) {
        const double dt = static_cast<double>(t_ns - last_t[j]) * 1e-9;
        for (std::size_t d = 0; d < 3; ++d) ja.rate_rad_s[d] = (now[d] - last[j][d]) / dt;
      }
      last[j] = now;
      last_t[j] = t_ns;
    }
  });
}
BENCHMARK(BM_JointRateFiniteDifferenceBaseline);

}  // namespace
}  // namespace mocap::kinematics

BENCHMARK_MAIN();
