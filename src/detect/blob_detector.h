// Design: the blob detector, an immutable configuration plus a workspace allocated
// once in create() from the stated bounds (image size, max_runs, max_blobs). detect()
// is the hot path: noexcept, no allocation, no locks.
//   1. threshold: fixed, or per frame from a sparse background histogram
//      (background.h);
//   2. a pass over the rows: SIMD kernels (row_runs.h) emit runs of bright pixels;
//      each run's background-subtracted moments are summed while the row is in
//      cache, and runs are united with the overlapping runs of the previous row
//      (8-connectivity, union-find with the smaller index as root). By default this
//      is the second of two passes: the first (chunk_max.h) reads every row once,
//      before the threshold is known, keeping the maximum of each 128-byte chunk and
//      giving the background histogram its sample rows on the way; the run kernels
//      then read only chunks whose maximum reaches the threshold (still in cache).
//      Dark chunks hold no bright pixel, so the runs are exactly those of a full
//      scan (cfg.full_scan, kept as the reference);
//   3. components are measured from their runs: area, bbox, peak, weighted centroid
//      (optionally with the 1-pixel ring just below threshold), second-moment shape;
//      filtered by size/border/elongation; merged markers flagged and split
//      (blob_measure.cpp).
// Usage:
//   auto det = BlobDetector::create(cfg, width, height);   // setup
//   BlobList blobs = det->make_blob_list();                 // setup
//   det->detect(image_view, blobs);                         // per frame
#pragma once

#include <cstdint>
#include <vector>

#include "core/expected.h"
#include "core/image.h"
#include "detect/background.h"
#include "detect/blob.h"
#include "detect/chunk_max.h"
#include "detect/detector_config.h"
#include "detect/row_runs.h"

namespace mocap::detect {

class BlobDetector {
 public:
  static Expected<BlobDetector> create(const DetectorConfig& cfg, int width, int height);

  // A BlobList with capacity cfg.max_blobs (setup-time allocation).
  BlobList make_blob_list() const { return BlobList(static_cast<std::size_t>(cfg_.max_blobs)); }

  // Detects the blobs of one frame into out (cleared first; at most out.capacity()).
  // Returns true when the whole frame was processed with nothing dropped; false for a
  // frame of the wrong size or null data (out empty) or when runs or blobs overflowed
  // (out holds what fit). Every outcome is counted in counters().
  bool detect(const ImageView& img, BlobList& out) noexcept;

  const DetectorCounters& counters() const noexcept { return counters_; }
  const DetectorConfig& config() const noexcept { return cfg_; }
  SimdLevel simd_level() const noexcept { return kernels_.level; }
  int width() const noexcept { return width_; }
  int height() const noexcept { return height_; }

  // Internal workspace records (public only so the measuring code can name them).
  struct RunRec {
    std::int32_t y, x_begin, x_end, parent;
    std::int64_t sw, swx, swxx;  // sums of w, w*x, w*x^2 over the run, w = pixel - bg
    std::uint32_t peak;
    std::int32_t comp;
  };
  struct CompAcc {
    double sw, swx, swy, swxx, swyy, swxy;
    std::int64_t area;
    int x_min, x_max, y_min, y_max;
    std::uint32_t peak;
    int first, count;  // slice of order_ (the component's runs, sorted by row then x)
  };

 private:
  BlobDetector() = default;

  template <class T>
  void summarise(const ImageView& img, bool sample_background) noexcept;
  template <class T>
  int row_kernel(const T* row, int x0, int x1, RowRun* out, int cap) const noexcept;
  template <class T>
  int bright_chunk_runs(const T* row, int y, int room) noexcept;
  template <class T>
  void scan(const ImageView& img) noexcept;
  void resolve_components() noexcept;
  template <class T>
  void measure(const ImageView& img, BlobList& out) noexcept;
  template <class T>
  void ring_moments(const ImageView& img, const CompAcc& c, double& sw, double& swx,
                    double& swy) noexcept;
  template <class T>
  bool try_split(const ImageView& img, const CompAcc& c, double cx, double cy, double l1, double l2,
                 double theta, Blob& a, Blob& b, bool& merged) noexcept;

  DetectorConfig cfg_{};
  int width_ = 0;
  int height_ = 0;
  Roi roi_{};
  RowRunKernels kernels_{};
  ChunkMaxKernels chunk_kernels_{};
  int chunks_per_row_ = 0;  // row stride of chunk_max_ (room for 16-bit chunks)
  BackgroundSampler sampler_;
  DetectorCounters counters_{};

  // Per-frame state.
  int threshold_ = 0;
  int background_ = 0;  // integer background used in the weights
  int n_runs_ = 0;
  int n_comps_ = 0;
  int overflow_row_ = -1;  // first row whose runs did not fit, -1 if none

  std::vector<RowRun> row_runs_;          // one row's runs
  std::vector<RunRec> runs_;              // max_runs
  std::vector<CompAcc> comps_;            // max_runs
  std::vector<std::int32_t> order_;       // max_runs: runs grouped by component
  std::vector<RowRun> row_span_;          // ring: per-row span of one component
  std::vector<double> profile_;           // split: profile along the major axis
  std::vector<std::uint16_t> chunk_max_;  // two-pass scan: per ROI row and chunk
  std::vector<std::uint16_t> row_max_;    // two-pass scan: per ROI row
};

}  // namespace mocap::detect
