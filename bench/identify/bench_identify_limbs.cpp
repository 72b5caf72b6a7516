// Design: Google Benchmark of Identifier::identify on the humanoid-like limb scene of
// tests/identify/limb_scene.h (limbs of 4-6 markers on short bases, markers at up to ~2
// m/s, swings of ~460 deg/s, target frames away from their markers, 100 fps), for 3, 15
// and 30 bodies: warm = the temporal path over a 10 s sequence, cold = a full search of
// every frame (temporal path off). Markers randomly hidden down to 3 per body, 0.2 mm
// noise, one stray point per body. Bodies beyond kMaxBodies are split over several
// Identifiers that all see every point. Counters: per-frame p50/p99 thread CPU time and,
// per body and frame, found / temporal-path / continuity shares and jump reboots.
#include <benchmark/benchmark.h>
#include <time.h>

#include <algorithm>
#include <random>

#include "identify/identifier.h"
#include "tests/identify/identify_test_util.h"
#include "tests/identify/limb_scene.h"

namespace mocap {
namespace {

double cpu_us() {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) * 1e6 + static_cast<double>(ts.tv_nsec) * 1e-3;
}

struct LimbFixture {
  std::vector<Identifier> ids;
  std::vector<test::Scene> frames;
  int bodies = 0;
};

LimbFixture make_fixture(int bodies, bool temporal, int frames) {
  std::mt19937_64 rng(500 + static_cast<unsigned>(bodies));
  const test::LimbScene limbs = test::make_limb_scene(rng, bodies);
  LimbFixture fx;
  fx.bodies = bodies;
  IdentifyConfig cfg;  // the tracker's limits (track/frame_processor.h)
  cfg.max_speed_mm_per_s = 3000.0;
  cfg.max_angular_speed_deg_per_s = 1440.0;
  cfg.temporal = temporal;
  for (int first = 0; first < bodies; first += kMaxBodies) {
    TargetSet part;
    for (int b = first; b < std::min(bodies, first + kMaxBodies); ++b)
      part.bodies.push_back(limbs.set.bodies[static_cast<std::size_t>(b)]);
    fx.ids.push_back(std::move(*Identifier::create(part, cfg)));
  }
  test::SceneOptions opt;
  opt.noise_mm = 0.2;
  opt.strays = bodies;
  opt.occlude = true;
  for (int f = 0; f < frames; ++f) {
    const auto poses = limbs.poses(f * 0.01);
    fx.frames.push_back(test::make_scene(rng, limbs.set, opt, &poses));
  }
  return fx;
}

void report(benchmark::State& state, const LimbFixture& fx, std::vector<double>& us) {
  std::sort(us.begin(), us.end());
  if (!us.empty()) {
    state.counters["p50_us"] = us[us.size() / 2];
    state.counters["p99_us"] = us[std::min(us.size() - 1, us.size() * 99 / 100)];
  }
  IdentifyCounters sum;
  for (const auto& id : fx.ids) {
    const auto& c = id.counters();
    sum.frames = c.frames;
    sum.bodies_found += c.bodies_found;
    sum.warm_accepted += c.warm_accepted;
    sum.jump_reboots += c.jump_reboots;
    sum.continuity_resolved += c.continuity_resolved;
  }
  const double body_frames = static_cast<double>(sum.frames) * fx.bodies;
  state.counters["found"] = static_cast<double>(sum.bodies_found) / body_frames;
  state.counters["warm"] = static_cast<double>(sum.warm_accepted) / body_frames;
  state.counters["contin"] = static_cast<double>(sum.continuity_resolved) / body_frames;
  state.counters["reboots"] = static_cast<double>(sum.jump_reboots) / body_frames;
  state.counters["points"] = static_cast<double>(fx.frames[0].pts.size());
}

void BM_LimbsWarm(benchmark::State& state) {
  LimbFixture fx = make_fixture(static_cast<int>(state.range(0)), true, 1000);
  BodyPoses out;
  std::vector<double> us;
  us.reserve(1 << 20);
  std::size_t i = 0;
  std::int64_t t = 0;
  for (auto _ : state) {
    if (i % fx.frames.size() == 0) {  // the sequence restarts: acquire again, untimed
      state.PauseTiming();
      for (auto& id : fx.ids) {
        id.reset();
        id.identify(fx.frames[0].pts.data(), static_cast<int>(fx.frames[0].pts.size()),
                    t += 10'000'000, out);
      }
      ++i;
      state.ResumeTiming();
    }
    const auto& s = fx.frames[i++ % fx.frames.size()];
    const double t0 = cpu_us();
    t += 10'000'000;
    for (auto& id : fx.ids) id.identify(s.pts.data(), static_cast<int>(s.pts.size()), t, out);
    const double t1 = cpu_us();
    benchmark::DoNotOptimize(out);
    if (us.size() < us.capacity()) us.push_back(t1 - t0);
  }
  report(state, fx, us);
}
BENCHMARK(BM_LimbsWarm)->Arg(3)->Arg(15)->Arg(30)->Unit(benchmark::kMicrosecond);

void BM_LimbsCold(benchmark::State& state) {
  LimbFixture fx = make_fixture(static_cast<int>(state.range(0)), false, 200);
  BodyPoses out;
  std::vector<double> us;
  us.reserve(1 << 20);
  std::size_t i = 0;
  std::int64_t t = 0;
  for (auto _ : state) {
    if (i % fx.frames.size() == 0)  // the sequence restarts: no jump for the speed limits
      for (auto& id : fx.ids) id.reset();
    const auto& s = fx.frames[i++ % fx.frames.size()];
    const double t0 = cpu_us();
    t += 10'000'000;
    for (auto& id : fx.ids) id.identify(s.pts.data(), static_cast<int>(s.pts.size()), t, out);
    const double t1 = cpu_us();
    benchmark::DoNotOptimize(out);
    if (us.size() < us.capacity()) us.push_back(t1 - t0);
  }
  report(state, fx, us);
}
BENCHMARK(BM_LimbsCold)->Arg(3)->Arg(15)->Arg(30)->Unit(benchmark::kMicrosecond);

}  // namespace
}  // namespace mocap
