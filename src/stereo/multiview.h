// Design: N-view correspondence for rigs with more than two cameras. The pairwise stereo
// stage (stereo_triangulator.h, one per camera pair) proposes 2-view candidates; this
// stage merges them into N-view points:
//   1. every pairwise candidate is a hypothesis (its two blobs);
//   2. each hypothesis is projected into every other camera; a blob within gate_px of
//      the projection (real pixels) joins it as a further view;
//   3. hypotheses with three or more views are refined over all of them (Gauss-Newton
//      on the real-pixel reprojection error, nview.h); a view whose residual exceeds
//      gate_px is dropped and the point refined again (an outlier never drags a point);
//   4. hypotheses are taken in order of more views, then smaller RMS (multiview_accept.cpp);
//      one whose blobs are all used by a taken point is the same point seen by another
//      pair (merged); one that shares a blob with a taken point seen by MORE cameras is a ghost,
//      rejected through the third view; one that shares a blob with a taken point seen
//      by as many cameras stays, and both are flagged ambiguous (not reported): the
//      identification resolves them by evidence, exactly as for two cameras.
// Unfit views of the same marker: a ball partly hidden from one camera has a centroid
// shifted by up to its image radius, beyond gate_px, so that camera's blob pairs with each
// of the other views into 2-view hypotheses a few millimetres off the marker (a triangle
// of pairings), and the detector may have split that blob in pieces. A later hypothesis
// made only of a taken point's blobs and, in cameras where the point has no view, blobs
// within gate_px + the ball's image radius (fx * marker_radius_mm / depth) of its
// projection, is that marker again (`unfit_pairings`), not a rival: the test is
// geometric, so every piece of a split blob counts, not only the nearest.
// Two balls whose images merge in some camera: that camera's one blob lies within gate_px
// of both balls' projections, so both points take it. The second one (in acceptance
// order) gives it up when it still stands on two views no taken point uses and the two
// points are at least a ball's diameter apart (two balls cannot be closer): it is refit
// over its own views and reported, not flagged as an ambiguous rival of the first.
// A 2-view point that no third camera confirms is still reported: under occlusion a
// camera that should see a marker often does not, so absence is no evidence, and a
// consistent pair of stray blobs is a point like any other for the identification,
// which rejects what fits no target. With two cameras there is nothing to add: the
// pair's candidates pass unchanged.
// Cost: linear in the blobs and hypotheses. The blobs of every camera are put in a
// uniform grid per frame (blob_grid.h), so the third-view lookup visits only the cells
// around the projection; the duplicate lookup (the first earlier hypothesis with the
// same blob set) is a hash table (blob_set_index.h); the acceptance takes the owners of
// a hypothesis's blobs from a blob -> point table. MergeSearch::kExhaustive runs the
// same steps by linear scans (every blob, every earlier hypothesis): the reference, with
// an identical result (tests/stereo/test_stereo_index.cpp).
// Settled blobs (MultiViewConfig::settle_blobs): most pairwise candidates are a marker
// already found from an earlier pair, or a ghost made of two found markers' blobs. A
// hypothesis that ends steps 1-3 with three or more views settles its blobs; a candidate
// of a LATER camera pair whose two blobs are both settled is not a hypothesis at all
// (counted in `settled`; the pairwise stage can skip triangulating it, SettledBlobs in
// stereo_triangulator.h, with the same result): either both blobs are that point's (it
// is found, by the pair that settled it) or each is another point's (a ghost, which the
// acceptance would reject against the points seen by more cameras). Blobs of one pair's
// candidates settle only the later pairs, so the result does not depend on the order of
// candidates within a pair. A marker is still found from the first pair with an unsettled
// blob; what settling can lose is a marker all of whose views are merged images of other
// points in every camera pair, which no rule can tell apart. The reference
// (settle_blobs = false, or
// MOCAP_MULTIVIEW_REFERENCE=1 in the environment at create(): a switch for end-to-end
// comparisons) takes every candidate (tests/stereo/test_multiview_settled.cpp).
// A frame can be given as the pairs' candidate lists (process()) or pair by pair
// (begin_frame(), add_pair(), finish()): the same result.
// Capacity is fixed in create(); process() is noexcept and allocation-free; overflows
// and rejections are counters. Each output point records its blob per camera.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "camera/camera_model.h"
#include "core/expected.h"
#include "stereo/blob_grid.h"
#include "stereo/blob_set_index.h"
#include "stereo/stereo_types.h"

namespace mocap {

// How the merge finds blobs near a projection and earlier hypotheses with the same blobs:
// spatial index and hash (default), or linear scans (the reference; same result).
enum class MergeSearch : std::uint8_t { kIndexed, kExhaustive };

struct MultiViewConfig {
  // A further view supports a point when one of its blobs lies within this distance of
  // the point's projection, and a refined view must stay within it: the same bound as
  // StereoConfig::max_reproj_px (real pixels), which the noise of a centroid (< 0.2 px)
  // and the calibration error stay far below.
  double gate_px = 2.0;
  int max_points_per_camera = 256;  // blobs per camera considered (as StereoConfig)
  int max_hypotheses = 2048;        // pairwise candidates considered per frame
  // Radius of the marker balls (mm; the targets' marker_diameter / 2): bounds how far a
  // partly hidden ball's centroid can move. 0: only blobs within gate_px count.
  double marker_radius_mm = 0.0;
  MergeSearch search = MergeSearch::kIndexed;
  // Cell of the per-camera blob grid (px): a few times the lookup radius (the gate plus
  // a ball's image radius), so a lookup visits one to four cells.
  double grid_cell_px = 64.0;
  // Candidates of two blobs settled by earlier pairs are no hypotheses (see the design
  // comment). false: every candidate is a hypothesis (the reference).
  bool settle_blobs = true;
};

struct MultiViewCounters {
  std::uint64_t frames = 0;
  std::uint64_t hypotheses = 0;           // pairwise candidates received
  std::uint64_t hypothesis_overflow = 0;  // beyond max_hypotheses (dropped)
  std::uint64_t views_added = 0;          // third and further views found by projection
  std::uint64_t views_dropped = 0;        // views removed as outliers after refinement
  std::uint64_t merged = 0;               // the same point from another camera pair
  std::uint64_t unfit_views = 0;          // nearest blobs beyond the gate, within the ball's image
  std::uint64_t unfit_pairings = 0;       // hypotheses made of a point and blobs of its image
  std::uint64_t shared_views_split = 0;   // points that gave up views another point took
  std::uint64_t ghosts_rejected = 0;      // lost to a point seen by more cameras
  std::uint64_t ambiguous = 0;            // emitted points flagged ambiguous
  std::uint64_t points = 0;               // emitted points
  std::uint64_t point_overflow = 0;       // emitted points beyond the output's capacity
  std::uint64_t blob_overflow = 0;        // blobs beyond max_points_per_camera (ignored)
  std::uint64_t settled = 0;              // candidates of two settled blobs (no hypothesis)
  // Camera frames whose blobs came without their undistortion (an UndistortedStore made
  // where they were detected), so the triangulation made it: FrameProcessor's count, not
  // the merger's (0 in the live pipeline and in `mocap track` on two threads).
  std::uint64_t undistorted_late = 0;
};

class MultiViewMerger {
 public:
  // Setup: 2..kMaxCameras cameras of the rig, a positive gate; allocates the workspace.
  static Expected<MultiViewMerger> create(const Rig& rig, const MultiViewConfig& config);

  // One frame. px[c][0..n[c]) are camera c's blob centroids (distorted pixels) for
  // c < camera_count(); pairs[0..pair_count) the pairwise candidates (blob_index by the
  // rig's camera index). Clears `out` and fills it. False when something was dropped
  // (hypotheses or output capacity); what was written is valid either way.
  bool process(const Vec2* const* px, const int* n, const PointList* const* pairs, int pair_count,
               PointList& out) noexcept;

  // The same frame in parts, for a caller that runs the camera pairs one by one (3+
  // cameras): begin_frame(), add_pair() after each pair, finish(). Between the pairs,
  // settled_blobs(c) says which blobs of camera c the pairs so far settled (for the next
  // pair's SettledBlobs). px and n as for process(), the same for every part of one
  // frame. finish() returns what process() returns; an empty pair list is allowed.
  void begin_frame(const Vec2* const* px, const int* n) noexcept;
  void add_pair(const PointList& pair, const Vec2* const* px) noexcept;
  bool finish(const Vec2* const* px, PointList& out) noexcept;
  // Per blob of camera c (its first max_points_per_camera): the hypothesis that settled
  // it this frame, -1: none. Valid until the next begin_frame(); all -1 in the reference.
  const int* settled_blobs(int c) const noexcept {
    return settled_by_.data() +
           static_cast<std::size_t>(c) * static_cast<std::size_t>(config_.max_points_per_camera);
  }

  // Refits p over exactly the views in p.blob_index (at least two; px as for process()):
  // Gauss-Newton on the real-pixel reprojection error from p.X_world; updates X_world and
  // reproj_px. Used when some views were found unfit afterwards (a partly hidden
  // marker's biased centroid) and the others suffice. False with fewer than two views
  // or a point behind a camera (p unchanged).
  bool refit(Point3& p, const Vec2* const* px) const noexcept;

  int camera_count() const noexcept { return static_cast<int>(cams_.size()); }
  const MultiViewCounters& counters() const noexcept { return counters_; }

 private:
  MultiViewMerger(const Rig& rig, const MultiViewConfig& config, std::vector<BlobGrid> grids,
                  BlobSetIndex same_index);
  // The first earlier hypothesis (< i) with the blob set extended_[i], or -1.
  int same_as_earlier(int i) noexcept;
  void extend(int i) noexcept;
  void refine(int i, const Vec2* const* px) noexcept;
  // gate_px plus the marker's image radius in camera c at X_world (0: behind).
  double unfit_gate_px(int c, const Vec3& X_world) const noexcept;
  // The same at depth z_mm (> 0) in camera c.
  double unfit_gate_at_depth_px(int c, double z_mm) const noexcept {
    return config_.gate_px +
           cams_[static_cast<std::size_t>(c)].fx * config_.marker_radius_mm / z_mm;
  }
  // Whether hypothesis i consists of taken point o's blobs and, in cameras where o has
  // no view, blobs within o's image (unfit_gate_px of its projection) only.
  bool is_unfit_pairing(int i, const Point3& o, const Vec2* const* px) const noexcept;
  // Two balls whose images merge in some views: h keeps only the views no taken point
  // uses, when each side stands on two views of its own and they are a ball's diameter
  // apart; refits h over them. False: h unchanged.
  bool split_from_owners(Point3& h, const int* owners, int n_owners, const PointList& out,
                         const Vec2* const* px) const noexcept;

  // Steps 1-3 for hypothesis i (its candidate in hyp_[i]).
  void merge_views(int i, const Vec2* const* px) noexcept;
  // Marks the views of hypothesis i (three or more) as settled by it.
  void settle(int i) noexcept;
  // Step 4 for hypothesis i; true when it was emitted.
  bool accept(int i, const Vec2* const* px, PointList& out, bool& complete) noexcept;

  std::vector<CameraModel> cams_;
  MultiViewConfig config_;
  std::vector<Point3> hyp_;         // workspace: this frame's hypotheses
  std::vector<int> views_;          // views per hypothesis
  std::vector<int> partial_views_;  // per hypothesis: cameras with only an unfit view
  std::vector<BlobRefs> extended_;  // blobs before refinement
  std::vector<int> out_hyp_;        // per output point: the hypothesis it came from
  struct AcceptKey {  // acceptance order: more views, more partly seen, smaller RMS, index
    int views;
    int partial;
    double reproj_px;
    int index;
  };
  std::vector<AcceptKey> order_;  // hypotheses in acceptance order
  std::vector<int> taken_by_;     // [camera * max_points_per_camera + blob]: output index
  std::vector<BlobGrid> grids_;   // per camera: this frame's blobs by image cell
  BlobSetIndex same_index_;       // this frame's extended blob sets -> first hypothesis
  std::vector<int> settled_by_;   // [camera * max_points_per_camera + blob]: hypothesis, -1
  int count_ = 0;                 // this frame's hypotheses so far
  bool complete_ = true;          // nothing dropped this frame
  MultiViewCounters counters_;
};

}  // namespace mocap
