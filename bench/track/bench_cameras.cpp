// Design: the per-frame work of the tracker against the camera count (issue 16's
// scaling benchmark). One frame of the simulator's built-in cameras (2: the stereo pair;
// 4 and 8: the arc around the robot, docs/simulator.md) of the default limbs scene is
// rendered once per camera count, with the model loaded, and FrameProcessor runs on it:
//  - BM_Frame/N: detection of every camera + correspondence + identification + angles
//    (FrameProcessor::process, one thread: the offline `mocap track`);
//  - BM_AfterDetect/N: the identify stage of the live pipeline alone (process_blobs:
//    pairwise stereo, N-view merge, identification, chain, angles) on the detected blobs.
// The 2-camera figures are the same-run baseline. Per-camera detection runs on the
// detect threads in the live pipeline, so BM_AfterDetect is what grows on one core.
#include <benchmark/benchmark.h>

#include <array>
#include <map>
#include <memory>

#include "sim/motion.h"
#include "sim/render.h"
#include "sim/simulate.h"
#include "track/frame_processor.h"

namespace mocap {
namespace {

struct CamerasFixture {
  sim::SimScene scene;
  std::vector<Image> images;
  std::vector<ImageView> views;
  std::vector<const ImageView*> present;
  std::unique_ptr<FrameProcessor> proc;
  FrameOutput out;
};

CamerasFixture& fixture(int cameras) {
  static std::map<int, std::unique_ptr<CamerasFixture>> all;
  std::unique_ptr<CamerasFixture>& slot = all[cameras];
  if (slot) return *slot;
  slot = std::make_unique<CamerasFixture>();
  CamerasFixture& f = *slot;
  sim::SimOptions opt;
  opt.cameras = cameras;
  auto scene = sim::make_scene(opt);
  if (!scene) std::abort();
  f.scene = std::move(scene).value();
  auto ws = sim::RenderWorkspace::create(f.scene);
  auto plan = sim::plan_motion(f.scene, sim::MotionSpec{});
  if (!ws || !plan) std::abort();
  sim::SceneState state = sim::make_state(f.scene);
  sim::apply_config(f.scene, plan->configs[10], state);
  state.noise_key = sim::frame_noise_key(1, 10);
  f.images.resize(static_cast<std::size_t>(cameras));
  f.views.resize(static_cast<std::size_t>(cameras));
  for (int c = 0; c < cameras; ++c) {
    const auto uc = static_cast<std::size_t>(c);
    f.images[uc] = sim::make_camera_image(f.scene, c);
    sim::render(f.scene, state, c, *ws, f.images[uc]);
    f.views[uc] = f.images[uc].view();
    f.present.push_back(&f.views[uc]);
  }
  auto proc =
      FrameProcessor::create(f.scene.rig, f.scene.targets, &f.scene.joints_true, TrackerConfig{});
  if (!proc) std::abort();
  f.proc = std::make_unique<FrameProcessor>(std::move(proc).value());
  f.out = f.proc->make_output();
  return f;
}

void BM_Frame(benchmark::State& state) {
  CamerasFixture& f = fixture(static_cast<int>(state.range(0)));
  std::int64_t ts = 0;
  for (auto _ : state) {
    f.proc->process(f.present, ts, f.out);
    ts += 10'000'000;
    benchmark::DoNotOptimize(f.out.points.size());
  }
  state.counters["points"] = f.out.points.size();
  state.counters["bodies"] = f.out.poses.found;
}
BENCHMARK(BM_Frame)->Arg(2)->Arg(4)->Arg(8)->Unit(benchmark::kMicrosecond);

void BM_AfterDetect(benchmark::State& state) {
  CamerasFixture& f = fixture(static_cast<int>(state.range(0)));
  std::int64_t ts = 0;
  f.proc->process(f.present, ts, f.out);  // the blobs stay in f.out
  for (auto _ : state) {
    ts += 10'000'000;
    f.proc->process_blobs(ts, f.out);
    benchmark::DoNotOptimize(f.out.points.size());
  }
  state.counters["points"] = f.out.points.size();
  state.counters["bodies"] = f.out.poses.found;
}
BENCHMARK(BM_AfterDetect)->Arg(2)->Arg(4)->Arg(8)->Unit(benchmark::kMicrosecond);

}  // namespace
}  // namespace mocap

BENCHMARK_MAIN();
