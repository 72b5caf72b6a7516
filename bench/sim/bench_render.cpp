// Benchmarks of the simulator's renderer: one stereo frame of the shoulder rig at the
// defaults (8 bits, 8x8 edge / 4x4 interior supersampling, blur 0.5 px), with stray
// reflections, at 16 bits, and the background-only cost (every marker dropped), which
// is the floor set by writing 2 x 1032 x 776 noisy pixels. Also the one-off workspace
// setup (exact undistortion of every pixel corner). Baseline: the same frame with
// uniform 8 x 8 supersampling of every pixel a disc touches.
#include <benchmark/benchmark.h>

#include "sim/render.h"
#include "sim/simulate.h"

namespace mocap::sim {
namespace {

void run_stereo(benchmark::State& st, SimOptions opt, int interior_samples = 0) {
  auto scene = make_scene(opt);
  if (!scene) {
    st.SkipWithError(scene.error().message.c_str());
    return;
  }
  if (interior_samples > 0) scene->imaging.supersample_interior = interior_samples;
  auto ws = RenderWorkspace::create(*scene);
  if (!ws) {
    st.SkipWithError(ws.error().message.c_str());
    return;
  }
  MotionSpec spec;
  spec.frames = 100;
  auto plan = plan_motion(*scene, spec);
  std::array<Image, 2> img = {make_camera_image(*scene, 0), make_camera_image(*scene, 1)};
  SceneState state = make_state(*scene);
  std::int64_t f = 0;
  for (auto _ : st) {
    apply_config(*scene, plan->configs[static_cast<std::size_t>(f % 100)], state);
    state.noise_key = frame_noise_key(opt.seed, f);
    bool ok = render(*scene, state, 0, *ws, img[0]);
    ok = render(*scene, state, 1, *ws, img[1]) && ok;
    benchmark::DoNotOptimize(ok);
    benchmark::DoNotOptimize(img[0].data());
    ++f;
  }
  st.SetItemsProcessed(st.iterations());
}

void BM_RenderStereoFrame(benchmark::State& st) { run_stereo(st, SimOptions{}); }
BENCHMARK(BM_RenderStereoFrame)->Unit(benchmark::kMillisecond);

// Baseline for the adaptive sampling: 8 x 8 samples in every pixel that a disc touches.
void BM_RenderStereoFrameUniform8x8(benchmark::State& st) { run_stereo(st, SimOptions{}, 8); }
BENCHMARK(BM_RenderStereoFrameUniform8x8)->Unit(benchmark::kMillisecond);

void BM_RenderStereoFrameStrays(benchmark::State& st) {
  SimOptions o;
  o.stray = 12;
  o.streak = true;
  run_stereo(st, o);
}
BENCHMARK(BM_RenderStereoFrameStrays)->Unit(benchmark::kMillisecond);

void BM_RenderStereoFrame16bit(benchmark::State& st) {
  SimOptions o;
  o.bits = 16;
  run_stereo(st, o);
}
BENCHMARK(BM_RenderStereoFrame16bit)->Unit(benchmark::kMillisecond);

void BM_RenderStereoBackgroundOnly(benchmark::State& st) {
  SimOptions o;
  o.dropout = 1.0;
  run_stereo(st, o);
}
BENCHMARK(BM_RenderStereoBackgroundOnly)->Unit(benchmark::kMillisecond);

void BM_WorkspaceSetup(benchmark::State& st) {
  auto scene = make_scene(SimOptions{});
  for (auto _ : st) {
    auto ws = RenderWorkspace::create(*scene);
    benchmark::DoNotOptimize(ws.ok());
  }
}
BENCHMARK(BM_WorkspaceSetup)->Unit(benchmark::kMillisecond)->Iterations(3);

}  // namespace
}  // namespace mocap::sim

BENCHMARK_MAIN();
