// Design: time of the wand calibration (calibrate_from_blobs: labelling, pairwise
// initialisation, joint bundle adjustment, quality) for 2 and 4 cameras on the same
// synthetic data: the 4-camera ring of tests/rigcal/rigcal_fixture.h, 400 wand frames,
// 0.08 px noise, the wand hidden from each camera in 15% of the frames, intrinsics fixed.
// The 2-camera case is cameras 0 and 1 of the same frames (the same-run baseline).
#include <benchmark/benchmark.h>

#include <vector>

#include "tests/rigcal/rigcal_fixture.h"

namespace mocap {
namespace {

void BM_CalibrateRig(benchmark::State& state) {
  const auto cameras = static_cast<std::size_t>(state.range(0));
  const auto ring = test::ring_cameras(4);
  const auto all = test::ring_wand_blobs(ring, test::test_wand(), 400, 0.08, 0.15, 21);
  const std::vector<CameraModel> cams(ring.begin(), ring.begin() + static_cast<long>(cameras));
  rigcal::FrameBlobs blobs;
  for (const auto& f : all) blobs.emplace_back(f.begin(), f.begin() + static_cast<long>(cameras));
  rigcal::RigCalOptions opt;
  opt.intrinsics = rigcal::IntrinsicsMode::kFixed;
  int used = 0;
  for (auto _ : state) {
    auto r = rigcal::calibrate_from_blobs(blobs, test::test_wand(), cams, opt, "bench");
    if (!r) {
      state.SkipWithError(r.error().message.c_str());
      return;
    }
    used = r->frames_used;
    benchmark::DoNotOptimize(r->cameras.back().t_cam_world);
  }
  state.counters["frames_used"] = used;
}
BENCHMARK(BM_CalibrateRig)->Arg(2)->Arg(4)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace mocap

BENCHMARK_MAIN();
