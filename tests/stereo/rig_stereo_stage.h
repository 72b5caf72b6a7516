// Test fixture shared by the stereo index tests and benchmarks: the stereo stage of a rig
// as FrameProcessor runs it (one StereoTriangulator per camera pair, then the
// MultiViewMerger), with each choice of the search open: blobs undistorted once per camera
// (BlobUndistorter views) or by every pair, the pairs' sorted sweep or all n*m pairs, the
// merge's index or its linear scans, settled blobs or the reference (multiview.h), and
// the frame given pair by pair (each pair skips the pairs of settled blobs: FrameProcessor's
// form) or as the pairs' lists (the merge skips those candidates: the same result).
#pragma once

#include <array>
#include <vector>

#include "stereo/multiview.h"
#include "stereo/stereo_triangulator.h"
#include "stereo/undistorted_blobs.h"

namespace mocap::test {

struct StagePath {
  bool shared_undistortion = true;
  MatchMethod match = MatchMethod::kSortedSweep;
  MergeSearch merge = MergeSearch::kIndexed;
  bool run_merge = true;     // false: the pairs only (benchmarks: where the time goes)
  bool settle = true;        // MultiViewConfig::settle_blobs (false: the reference merge)
  bool pair_by_pair = true;  // begin_frame/add_pair/finish with SettledBlobs; else process()
};
// Today's path: undistorted once per camera, sorted sweep, indexed merge, pair by pair.
inline constexpr StagePath kIndexedPath{};
// The same search with every pair undistorting its blobs (the pointer form of process()).
inline constexpr StagePath kPairUndistortPath{false, MatchMethod::kSortedSweep,
                                              MergeSearch::kIndexed};
// The search before the index: pairs undistort, sorted sweep, linear-scan merge, the
// pairs' lists given at once.
inline constexpr StagePath kLinearMergePath{
    false, MatchMethod::kSortedSweep, MergeSearch::kExhaustive, true, true, false};
// Today's search with the reference merge: every candidate a hypothesis (no settling).
inline constexpr StagePath kReferencePath{true, MatchMethod::kSortedSweep, MergeSearch::kIndexed,
                                          true, false};
// The pairs of the indexed path alone (nothing settles without the merge).
inline constexpr StagePath kPairsOnlyPath{true, MatchMethod::kSortedSweep, MergeSearch::kIndexed,
                                          false, false};
// Brute force of everything: all n*m pairs, linear-scan merge, the lists at once.
inline constexpr StagePath kBruteForcePath{
    false, MatchMethod::kExhaustive, MergeSearch::kExhaustive, true, true, false};

struct RigStereoStage {
  StagePath path;
  std::vector<BlobUndistorter> undistort;
  std::vector<StereoTriangulator> pairs;
  std::vector<PointList> pair_out;
  MultiViewMerger merger;
  PointList out{4096};

  static MultiViewConfig merge_config(const StagePath& path, std::size_t cameras) {
    MultiViewConfig c;
    c.marker_radius_mm = 7.0;
    c.max_hypotheses = 1024 * static_cast<int>(cameras * (cameras - 1) / 2);  // as FrameProcessor
    c.search = path.merge;
    c.settle_blobs = path.settle;
    return c;
  }

  RigStereoStage(const Rig& rig, const StagePath& p)
      : path(p), merger(MultiViewMerger::create(rig, merge_config(p, rig.cameras.size())).value()) {
    StereoConfig sc;
    sc.method = p.match;
    std::array<CameraPair, kMaxCameraPairs> cp{};
    const int np = enumerate_camera_pairs(static_cast<int>(rig.cameras.size()), cp);
    for (int k = 0; k < np; ++k) {
      const CameraPair& q = cp[static_cast<std::size_t>(k)];
      pairs.push_back(StereoTriangulator::create(rig, sc, q.a, q.b).value());
      pair_out.emplace_back(1024);
    }
    for (const CameraModel& cam : rig.cameras)
      undistort.push_back(BlobUndistorter::create(cam, sc.max_points_per_camera).value());
  }

  // One frame: px[c] are camera c's blobs (distorted pixels).
  void run(const std::vector<std::vector<Vec2>>& px) noexcept {
    const Vec2* p[kMaxCameras] = {};
    int n[kMaxCameras] = {};
    UndistortedBlobs views[kMaxCameras];
    for (std::size_t c = 0; c < px.size() && c < kMaxCameras; ++c) {
      p[c] = px[c].data();
      n[c] = static_cast<int>(px[c].size());
      if (path.shared_undistortion) views[c] = undistort[c].undistort(p[c], n[c]);
    }
    const bool by_pair = path.run_merge && path.pair_by_pair;
    if (by_pair) merger.begin_frame(p, n);
    const PointList* lists[kMaxCameraPairs] = {};
    for (std::size_t k = 0; k < pairs.size(); ++k) {
      const int a = pairs[k].camera_a(), b = pairs[k].camera_b();
      const SettledBlobs settled =
          by_pair ? SettledBlobs{merger.settled_blobs(a), merger.settled_blobs(b)} : SettledBlobs{};
      if (path.shared_undistortion)
        pairs[k].process(views[a], views[b], pair_out[k], settled);
      else
        pairs[k].process(p[a], n[a], p[b], n[b], pair_out[k], settled);
      lists[k] = &pair_out[k];
      if (by_pair) merger.add_pair(pair_out[k], p);
    }
    if (by_pair)
      merger.finish(p, out);
    else if (path.run_merge)
      merger.process(p, n, lists, static_cast<int>(pairs.size()), out);
  }
};

}  // namespace mocap::test
