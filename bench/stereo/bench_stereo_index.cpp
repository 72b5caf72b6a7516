// Design: per-frame cost of the whole stereo stage for "the whole robot": markers in a
// humanoid volume (0.6 x 1.8 x 0.6 m), 2/4/6/8 cameras on a ring 3 m away (1280x1024,
// f ~ 1250 px), 0.1 px noise, 4 stray blobs per image; 15, 70 and 150 markers, each on
// the body's surface and seen by the cameras in front of it (all_visible:0, the half-space
// of its outward normal: about half the ring) or by every camera (all_visible:1). Every
// camera pair's triangulator plus the N-view merge (tests/stereo/rig_stereo_stage.h), in
// several forms measured in the same run (the merge alone: a row minus PairsOnly):
//  - BM_StereoRigIndexed: blobs undistorted once per camera, sorted sweep, indexed merge,
//    pair by pair with settled blobs (multiview.h: later pairs skip two settled blobs);
//  - BM_StereoRigReference: the same without settling (the reference merge);
//  - BM_StereoRigPairUndistort: the same, every pair undistorting its blobs;
//  - BM_StereoRigLinearMerge: the search before the index (pairs undistort, sorted
//    sweep, linear-scan merge);
//  - BM_StereoRigBruteForce: all n*m pairs and linear-scan merge.
// The counter points_per_frame is the merge's output; settled_per_frame the pairs of two
// settled blobs (skipped by the pairs, or dropped by a merge given the lists).
#include <benchmark/benchmark.h>

#include <algorithm>
#include <random>
#include <vector>

#include "tests/stereo/humanoid_scene.h"
#include "tests/stereo/rig_stereo_stage.h"

namespace mocap {
namespace {

void run_rig_stage(benchmark::State& state, const test::StagePath& path) {
  const int cameras = static_cast<int>(state.range(0));
  const int markers = static_cast<int>(state.range(1));
  const bool all_visible = state.range(2) != 0;
  std::mt19937 rng(static_cast<unsigned>(1000 * cameras + markers));  // same rig per row
  test::RingOptions ro;
  ro.cameras = cameras;
  const Rig rig = test::humanoid_ring_rig(ro, rng);
  test::SceneOptions so;
  so.markers = markers;
  so.facing_deg = all_visible ? 180.0 : 90.0;
  constexpr int kFrames = 8;
  std::vector<std::vector<std::vector<Vec2>>> frames;
  int blobs = 0;
  for (int f = 0; f < kFrames; ++f) {
    frames.push_back(test::humanoid_frame(rig, so, rng));
    for (const auto& cam : frames.back()) blobs += static_cast<int>(cam.size());
  }
  test::RigStereoStage stage(rig, path);
  std::int64_t points = 0;
  int f = 0;
  for (auto _ : state) {
    stage.run(frames[static_cast<std::size_t>(f)]);
    points += stage.out.size();
    benchmark::DoNotOptimize(stage.out.size());
    f = (f + 1) % kFrames;
  }
  state.SetItemsProcessed(state.iterations());
  state.counters["points_per_frame"] =
      static_cast<double>(points) / static_cast<double>(state.iterations());
  state.counters["blobs_per_camera"] = static_cast<double>(blobs) / (kFrames * cameras);
  state.counters["views_per_marker"] =
      static_cast<double>(blobs - kFrames * cameras * so.strays) / (kFrames * markers);
  const auto frames_run =
      static_cast<double>(std::max<std::uint64_t>(1, stage.merger.counters().frames));
  state.counters["hypotheses_per_frame"] =
      static_cast<double>(stage.merger.counters().hypotheses) / frames_run;
  // Settled blobs: the a-blobs the pairs searched among unsettled b-blobs only (pair by
  // pair), or the candidates the merge dropped (lists).
  std::uint64_t settled = stage.merger.counters().settled;
  for (const StereoTriangulator& st : stage.pairs) settled += st.counters().settled_blobs;
  state.counters["settled_per_frame"] = static_cast<double>(settled) / frames_run;
}

void BM_StereoRigIndexed(benchmark::State& s) { run_rig_stage(s, test::kIndexedPath); }
void BM_StereoRigReference(benchmark::State& s) { run_rig_stage(s, test::kReferencePath); }
void BM_StereoRigPairUndistort(benchmark::State& s) { run_rig_stage(s, test::kPairUndistortPath); }
void BM_StereoRigLinearMerge(benchmark::State& s) { run_rig_stage(s, test::kLinearMergePath); }
void BM_StereoRigPairsOnly(benchmark::State& s) { run_rig_stage(s, test::kPairsOnlyPath); }
void BM_StereoRigBruteForce(benchmark::State& s) { run_rig_stage(s, test::kBruteForcePath); }

#define MOCAP_RIG_ROWS(fn)                                 \
  BENCHMARK(fn)                                            \
      ->ArgsProduct({{2, 4, 6, 8}, {15, 70, 150}, {0, 1}}) \
      ->ArgNames({"cameras", "markers", "all_visible"})    \
      ->Unit(benchmark::kMicrosecond)
MOCAP_RIG_ROWS(BM_StereoRigIndexed);
MOCAP_RIG_ROWS(BM_StereoRigReference);
MOCAP_RIG_ROWS(BM_StereoRigPairUndistort);
MOCAP_RIG_ROWS(BM_StereoRigLinearMerge);
MOCAP_RIG_ROWS(BM_StereoRigBruteForce);
MOCAP_RIG_ROWS(BM_StereoRigPairsOnly);
#undef MOCAP_RIG_ROWS

}  // namespace
}  // namespace mocap
