// Design: the innermost loop of detection. A row kernel turns one image row into
// runs of bright pixels (value >= threshold) and skips dark pixels many at a time:
// AVX2 compares 32 pixels per step (8-bit: one load; 16-bit: two loads packed to one
// mask), SSE2 16, and the portable scalar kernel one. All kernels produce exactly the
// same runs; the choice is made once at setup (runtime CPU check for AVX2).
#pragma once

#include <cstdint>

#include "detect/detector_config.h"

namespace mocap::detect {

struct RowRun {
  std::int32_t x_begin;  // first bright pixel
  std::int32_t x_end;    // one past the last bright pixel
};

// Finds the bright runs of row[x0, x1) (x in absolute columns). Writes at most cap
// runs to out and returns how many it wrote, or cap + 1 when the row has more runs
// than cap (then the first cap runs are written). 1 <= threshold, and threshold <= 255
// for 8-bit rows.
using RowRunKernel8 = int (*)(const std::uint8_t* row, int x0, int x1, std::uint16_t threshold,
                              RowRun* out, int cap) noexcept;
using RowRunKernel16 = int (*)(const std::uint16_t* row, int x0, int x1, std::uint16_t threshold,
                               RowRun* out, int cap) noexcept;

struct RowRunKernels {
  RowRunKernel8 k8;
  RowRunKernel16 k16;
  SimdLevel level;  // the level actually used (kAuto resolved)
};

// Resolves kAuto to the best level this CPU supports. Asking for a level the CPU or
// the build lacks falls back to the next lower one.
RowRunKernels select_row_run_kernels(SimdLevel requested) noexcept;

const char* simd_level_name(SimdLevel level) noexcept;

}  // namespace mocap::detect
