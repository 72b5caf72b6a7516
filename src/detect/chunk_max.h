// Design: the first pass of the detector's two-pass scan. A chunk kernel reads one
// image row once and writes the exact maximum of every chunk of kChunkPx8 (8-bit) or
// kChunkPx16 (16-bit) pixels, i.e. 128 bytes, counted from the ROI's first column
// (the last chunk may be shorter), and returns the row's maximum. The threshold is
// not needed yet, so this pass can run before the background estimate is known and
// read the rows the estimate samples in the same sweep; afterwards only chunks whose
// maximum reaches the threshold are scanned for runs (row_runs.h), from cache. AVX2
// loads 4 x 32 bytes per chunk and reduces two chunks at a time; the scalar kernel is
// the portable fallback; both give identical maxima. Chosen once at setup.
#pragma once

#include <cstdint>

#include "detect/detector_config.h"

namespace mocap::detect {

inline constexpr int kChunkPx8 = 128;
inline constexpr int kChunkPx16 = 64;

// Chunks of a row [x0, x1) of chunk_px pixels each (the last one possibly shorter).
constexpr int chunk_count(int x0, int x1, int chunk_px) noexcept {
  return (x1 - x0 + chunk_px - 1) / chunk_px;
}

// Writes chunk_count(x0, x1, kChunkPx*) maxima to out and returns the row's maximum.
// x0 < x1; reads row[x0, x1) only.
using ChunkMaxKernel8 = std::uint16_t (*)(const std::uint8_t* row, int x0, int x1,
                                          std::uint16_t* out) noexcept;
using ChunkMaxKernel16 = std::uint16_t (*)(const std::uint16_t* row, int x0, int x1,
                                           std::uint16_t* out) noexcept;

struct ChunkMaxKernels {
  ChunkMaxKernel8 k8;
  ChunkMaxKernel16 k16;
};

// AVX2 when requested (kAuto/kAvx2) and supported, else the scalar kernels.
ChunkMaxKernels select_chunk_max_kernels(SimdLevel requested) noexcept;

}  // namespace mocap::detect
