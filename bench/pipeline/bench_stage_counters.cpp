// The per-frame cost the pipeline's fault accounting adds to its stage threads:
//   TimestampCheck      : the capture stage's clock-step test, per camera frame;
//   DetectorMirror      : detect c republishing the detector's 13 counters per frame;
//   IdentifyMirrors     : identify republishing the stereo (14) and identification (16)
//                         counters per frame;
//   PlainCopy (baseline): copying the same three structs with plain (non-atomic)
//                         assignments, what an unsynchronised snapshot would cost.
// Counters that change every iteration keep the compiler from hoisting the loads.
#include <benchmark/benchmark.h>

#include "pipeline/stage_counters.h"
#include "pipeline/timestamp_check.h"

namespace mocap::pipeline {
namespace {

void BM_TimestampCheck(benchmark::State& state) {
  TimestampCheck check(10'000'000);
  std::uint64_t sequence = 0;
  std::int64_t t = 1'000'000'000;
  for (auto _ : state) {
    t += 10'000'000;
    benchmark::DoNotOptimize(check.check(++sequence, t, t + 500'000, t));
  }
}
BENCHMARK(BM_TimestampCheck);

void BM_DetectorMirror(benchmark::State& state) {
  detect::DetectorCounters d{};
  DetectorMirror mirror;
  for (auto _ : state) {
    ++d.frames;
    d.components += 12;
    benchmark::DoNotOptimize(&d);
    mirror.publish(kDetectorFields, d);
    benchmark::ClobberMemory();
  }
}
BENCHMARK(BM_DetectorMirror);

void BM_IdentifyMirrors(benchmark::State& state) {
  StereoCounters s{};
  IdentifyCounters i{};
  StereoMirror stereo;
  IdentifyMirror identify;
  for (auto _ : state) {
    ++s.frames;
    ++i.frames;
    benchmark::DoNotOptimize(&s);
    benchmark::DoNotOptimize(&i);
    stereo.publish(kStereoFields, s);
    identify.publish(kIdentifyFields, i);
    benchmark::ClobberMemory();
  }
}
BENCHMARK(BM_IdentifyMirrors);

void BM_PlainCopyBaseline(benchmark::State& state) {
  detect::DetectorCounters d{}, d_copy{};
  StereoCounters s{}, s_copy{};
  IdentifyCounters i{}, i_copy{};
  for (auto _ : state) {
    ++d.frames;
    ++s.frames;
    ++i.frames;
    benchmark::DoNotOptimize(&d);
    benchmark::DoNotOptimize(&s);
    benchmark::DoNotOptimize(&i);
    d_copy = d;
    s_copy = s;
    i_copy = i;
    benchmark::DoNotOptimize(&d_copy);
    benchmark::DoNotOptimize(&s_copy);
    benchmark::DoNotOptimize(&i_copy);
    benchmark::ClobberMemory();
  }
}
BENCHMARK(BM_PlainCopyBaseline);

}  // namespace
}  // namespace mocap::pipeline

BENCHMARK_MAIN();
