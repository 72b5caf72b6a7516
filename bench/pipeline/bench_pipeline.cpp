// End-to-end latency of the live pipeline on the simulated stereo pair (a pre-rendered
// loop of the built-in scenario, the simulator's true model): N frames are triggered,
// and the benchmark reports p50/p99/max of trigger -> published (and of each stage) as
// counters, in microseconds. Two pacings:
//   Periodic/<rate>: the deployment case, software trigger at <rate> Hz;
//   Lockstep:        one frame in flight at a time (the latency of an idle pipeline;
//                    its fps is the throughput bound of one-frame-at-a-time operation);
//   Cameras/<n>:     periodic at 100 Hz with n = 2, 4, 8 simulated cameras (the built-in
//                    pair / arc, 1032x776; issue 16's scaling, baseline: 2 cameras).
// The stage table is applied (pinning, SCHED_FIFO) when permitted. The sink is a no-op
// (the UDP cost is measured by the publisher's own benchmark). Baseline: the paper's
// 20-30 ms end-to-end latency, reported as paper_ratio = 25 ms / p50.
#include <benchmark/benchmark.h>

#include <chrono>
#include <map>
#include <thread>
#include <vector>

#include "hal/sim_camera.h"
#include "pipeline/pipeline.h"

namespace mocap::pipeline {
namespace {

class NullSink final : public publish::OutputSink {
 public:
  const char* name() const noexcept override { return "null"; }
  publish::OutputCounters counters() const noexcept override { return {}; }
  bool publish(const publish::FrameResult&) noexcept override { return true; }
};

// The pre-rendered loop of `cameras` simulated cameras (rendered once per count).
std::shared_ptr<const hal::SimFrameLoop> loop(int cameras = 2) {
  static std::map<int, std::shared_ptr<const hal::SimFrameLoop>> loops;
  auto& l = loops[cameras];
  if (!l) {
    sim::SimOptions o;
    o.frames = cameras == 2 ? 100 : 40;
    o.cameras = cameras;
    auto r = hal::SimFrameLoop::render(o);
    if (r.ok()) l = *r;
  }
  return l;
}

void run(benchmark::State& state, TriggerPacing pacing, double rate_hz, std::uint64_t frames,
         int cameras = 2) {
  if (!loop(cameras)) {
    state.SkipWithError("sim loop failed");
    return;
  }
  PipelineStats st;
  for (auto _ : state) {
    auto trigger = std::make_shared<hal::SimTrigger>(loop(cameras));
    std::vector<std::unique_ptr<hal::SimCamera>> cams;
    std::vector<hal::Camera*> cam_ptrs;
    for (int c = 0; c < cameras; ++c) {
      cams.push_back(std::move(hal::SimCamera::open(trigger, c)).value());
      hal::CameraConfig cfg = cams.back()->native_config();
      cfg.buffer_count = 6;
      (void)cams.back()->configure(cfg);
      cam_ptrs.push_back(cams.back().get());
    }
    const sim::SimScene& sc = loop(cameras)->scene();
    auto proc = FrameProcessor::create(sc.rig, sc.targets, &sc.joints_true, TrackerConfig{});
    NullSink sink;
    PipelineOptions opt;
    opt.pacing = pacing;
    opt.trigger_rate_hz = rate_hz;
    opt.max_frames = frames;
    opt.lock_memory = false;
    auto p = Pipeline::create(std::move(proc).value(), cam_ptrs, {&sink}, opt);
    if (!p || !(*p)->start()) {
      state.SkipWithError("pipeline start failed");
      return;
    }
    while (!(*p)->finished()) std::this_thread::sleep_for(std::chrono::milliseconds(5));
    (*p)->stop();
    st = (*p)->stats();
  }
  for (const auto& [name, l] : st.latency) {
    if (name == "publish") {
      state.counters["e2e_p50_us"] = l.p50_us;
      state.counters["e2e_p99_us"] = l.p99_us;
      state.counters["e2e_max_us"] = l.max_us;
      state.counters["paper_ratio"] = 25000.0 / l.p50_us;
    } else if (name == "detect0" || name == "identify") {
      state.counters[name + "_p50_us"] = l.p50_us;
      state.counters[name + "_p99_us"] = l.p99_us;
    }
  }
  for (const auto& [name, v] : st.counters)
    if (name == "frames_dropped") state.counters["dropped"] = static_cast<double>(v);
  state.counters["published"] = static_cast<double>(st.published);
  state.counters["fps"] = st.fps;
}

void BM_PipelinePeriodic(benchmark::State& state) {
  run(state, TriggerPacing::kPeriodic, static_cast<double>(state.range(0)), 1000);
}
BENCHMARK(BM_PipelinePeriodic)
    ->Arg(100)
    ->Arg(200)
    ->Iterations(1)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

void BM_PipelineLockstep(benchmark::State& state) {
  run(state, TriggerPacing::kLockstep, 10000.0, 1000);
}
BENCHMARK(BM_PipelineLockstep)->Iterations(1)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_PipelineCameras(benchmark::State& state) {
  run(state, TriggerPacing::kPeriodic, 100.0, 1000, static_cast<int>(state.range(0)));
}
BENCHMARK(BM_PipelineCameras)
    ->Arg(2)
    ->Arg(4)
    ->Arg(8)
    ->Iterations(1)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

}  // namespace
}  // namespace mocap::pipeline

BENCHMARK_MAIN();
