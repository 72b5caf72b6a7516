// Design: per-frame cost of N-view correspondence (stereo/multiview.h) with 2 and 4
// cameras: one StereoTriangulator per camera pair plus the MultiViewMerger, n markers in
// the working volume seen by every camera that has them in its image (0.1 px noise) and
// 3 stray blobs per image. The 2-camera case is today's stereo stage plus the merger's
// pass-through (the baseline of the same run); 4 cameras run 6 pairs and the merge.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <random>
#include <vector>

#include "stereo/multiview.h"
#include "stereo/stereo_triangulator.h"
#include "tests/stereo/stereo_test_rig.h"

namespace mocap {
namespace {

void BM_MultiViewFrame(benchmark::State& state) {
  const int cameras = static_cast<int>(state.range(0));
  const int n = static_cast<int>(state.range(1));
  const Rig rig = cameras == 2 ? test::paper_rig() : test::ring_rig();
  std::array<CameraPair, kMaxCameraPairs> cp{};
  const int np = enumerate_camera_pairs(cameras, cp);
  std::vector<StereoTriangulator> pairs;
  std::vector<PointList> pair_out;
  for (int k = 0; k < np; ++k) {
    const CameraPair& p = cp[static_cast<std::size_t>(k)];
    pairs.push_back(StereoTriangulator::create(rig, StereoConfig{}, p.a, p.b).value());
    pair_out.emplace_back(1024);
  }
  auto merger = MultiViewMerger::create(rig, MultiViewConfig{}).value();
  PointList out(4096);
  constexpr int kFrames = 16;
  std::mt19937 rng(static_cast<unsigned>(n));
  std::uniform_real_distribution<double> ux(-250.0, 250.0), uz(800.0, 1200.0), u01(0.0, 1.0);
  std::normal_distribution<double> noise(0.0, 0.1);
  std::vector<std::vector<std::vector<Vec2>>> px(
      kFrames, std::vector<std::vector<Vec2>>(rig.cameras.size()));
  for (auto& frame : px) {
    for (int i = 0; i < n; ++i) {
      const Vec3 X(ux(rng), ux(rng), uz(rng));
      for (std::size_t c = 0; c < rig.cameras.size(); ++c) {
        Vec2 p;
        if (project(rig.cameras[c], X, p) && test::in_image(rig.cameras[c], p))
          frame[c].push_back(p + Vec2(noise(rng), noise(rng)));
      }
    }
    for (auto& blobs : frame) {
      for (int s = 0; s < 3; ++s) blobs.push_back(Vec2(u01(rng) * 1031.0, u01(rng) * 775.0));
      std::shuffle(blobs.begin(), blobs.end(), rng);
    }
  }
  std::int64_t points = 0;
  int f = 0;
  for (auto _ : state) {
    const Vec2* p[kMaxCameras] = {};
    int count[kMaxCameras] = {};
    for (int c = 0; c < cameras; ++c) {
      p[c] = px[static_cast<std::size_t>(f)][static_cast<std::size_t>(c)].data();
      count[c] =
          static_cast<int>(px[static_cast<std::size_t>(f)][static_cast<std::size_t>(c)].size());
    }
    const PointList* lists[kMaxCameraPairs] = {};
    for (std::size_t k = 0; k < pairs.size(); ++k) {
      const int a = pairs[k].camera_a(), b = pairs[k].camera_b();
      pairs[k].process(p[a], count[a], p[b], count[b], pair_out[k]);
      lists[k] = &pair_out[k];
    }
    merger.process(p, count, lists, np, out);
    points += out.size();
    f = (f + 1) % kFrames;
  }
  state.SetItemsProcessed(state.iterations());
  state.counters["points_per_frame"] =
      static_cast<double>(points) / static_cast<double>(state.iterations());
}
BENCHMARK(BM_MultiViewFrame)
    ->ArgsProduct({{2, 4}, {15, 50}})
    ->ArgNames({"cameras", "n"})
    ->Unit(benchmark::kMicrosecond);

}  // namespace
}  // namespace mocap
