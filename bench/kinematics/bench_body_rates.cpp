// Benchmark of the body-velocity filter (kinematics/body_rates.h) on the humanoid's 15
// bodies per frame, against a same-run baseline: finite differences of consecutive poses
// (position difference and the rotation vector of R_now R_last^T over dt; no noise model,
// no sd). Counters p50_us / p99_us are per frame.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <vector>

#include "kinematics/body_rates.h"

namespace mocap::kinematics {
namespace {

constexpr std::size_t kBodies = 15;

// Frame k of a smooth motion of every body (a limb swinging and turning), now and then lost.
void humanoid_bodies(int k, std::vector<BodyMeasurement>& m) {
  for (std::size_t b = 0; b < m.size(); ++b) {
    const double t = 0.01 * k, f = 0.3 + 0.05 * static_cast<double>(b);
    Iso3 T = Iso3::Identity();
    T.translation() = Vec3(200.0 * std::sin(6.283 * f * t), 150.0 * std::cos(6.283 * f * t),
                           900.0 + 100.0 * static_cast<double>(b));
    T.linear() = (Eigen::AngleAxisd(1.1 * std::sin(6.283 * f * t), Vec3::UnitZ()) *
                  Eigen::AngleAxisd(0.5 * std::sin(6.283 * 1.3 * f * t), Vec3::UnitX()))
                     .toRotationMatrix();
    m[b] = {(k + static_cast<int>(b)) % 97 != 0, T, 0.1, 1e-3};
  }
}

template <typename Update>
void run_bodies(benchmark::State& state, Update update) {
  constexpr int kFrames = 1000;  // 10 s at 100 fps, replayed
  std::vector<std::vector<BodyMeasurement>> frames(kFrames, std::vector<BodyMeasurement>(kBodies));
  for (int k = 0; k < kFrames; ++k) humanoid_bodies(k, frames[static_cast<std::size_t>(k)]);
  std::vector<BodyRate> out(kBodies);
  std::vector<double> us;
  us.reserve(1 << 16);
  std::int64_t k = 0;
  for (auto _ : state) {
    const auto& f = frames[static_cast<std::size_t>(k % kFrames)];
    const auto t0 = std::chrono::steady_clock::now();
    update(k * 10'000'000, f, out);
    const auto t1 = std::chrono::steady_clock::now();
    benchmark::DoNotOptimize(out.data());
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

void BM_BodyRateFilterHumanoid(benchmark::State& state) {
  auto filter = BodyRateFilter::create({}, kBodies);
  run_bodies(state, [&](std::int64_t t_ns, const std::vector<BodyMeasurement>& m,
                        std::vector<BodyRate>& out) { filter->update(t_ns, m, out); });
}
BENCHMARK(BM_BodyRateFilterHumanoid);

void BM_BodyRateFiniteDifferenceBaseline(benchmark::State& state) {
  std::vector<Iso3> last(kBodies, Iso3::Identity());
  std::vector<std::int64_t> last_t(kBodies, -1);
  run_bodies(state, [&](std::int64_t t_ns, const std::vector<BodyMeasurement>& m,
                        std::vector<BodyRate>& out) {
    for (std::size_t b = 0; b < m.size(); ++b) {
      out[b].valid = false;
      if (!m[b].found) continue;
      if (last_t[b] >= 0) {
        const double dt = static_cast<double>(t_ns - last_t[b]) * 1e-9;
        const Eigen::AngleAxisd turn(m[b].T_world_body.linear() * last[b].linear().transpose());
        out[b].v_world_mm_s = (m[b].T_world_body.translation() - last[b].translation()) / dt;
        out[b].w_world_rad_s = turn.axis() * (turn.angle() / dt);
        out[b].valid = true;
      }
      last[b] = m[b].T_world_body;
      last_t[b] = t_ns;
    }
  });
}
BENCHMARK(BM_BodyRateFiniteDifferenceBaseline);

}  // namespace
}  // namespace mocap::kinematics
