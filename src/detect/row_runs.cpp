// Design: see row_runs.h. The SIMD kernels compute a bit mask per chunk of pixels
// (bit i set = pixel i bright), skip chunks that are all dark outside a run (or all
// bright inside one), and otherwise walk the mask's transitions with count-trailing-
// zeros. The tail of a row shorter than a chunk is finished by the scalar loop, which
// carries the open run over, so every kernel yields identical runs. AVX2 code is
// compiled with a function target attribute and only called after a CPU check.
#include "detect/row_runs.h"

#if defined(__x86_64__) || defined(__i386__)
#include <immintrin.h>
#define MOCAP_DETECT_X86 1
#endif

namespace mocap::detect {
namespace {

// Run state carried across chunks of one row.
struct RunState {
  RowRun* out;
  int cap;
  int count = 0;
  bool in_run = false;
  int start = 0;

  // Returns false when out is full (count becomes cap + 1).
  bool emit(int end) noexcept {
    in_run = false;
    if (count >= cap) {
      count = cap + 1;
      return false;
    }
    out[count++] = RowRun{start, end};
    return true;
  }
};

// Processes n_bits (<= 32) pixels starting at column x with bright mask m.
inline bool walk_mask(std::uint64_t m, int n_bits, int x, RunState& s) noexcept {
  const std::uint64_t full = (std::uint64_t{1} << n_bits) - 1;
  if (!s.in_run) {
    if (m == 0) return true;
  } else if (m == full) {
    return true;
  }
  std::uint64_t from = full;  // bits at or after the current position
  for (;;) {
    if (!s.in_run) {
      const std::uint64_t b = m & from;
      if (b == 0) return true;
      const int p = __builtin_ctzll(b);
      s.in_run = true;
      s.start = x + p;
      from = full & (~std::uint64_t{0} << p);
    } else {
      const std::uint64_t z = ~m & from;
      if (z == 0) return true;
      const int p = __builtin_ctzll(z);
      if (!s.emit(x + p)) return false;
      from = full & (~std::uint64_t{0} << p);
    }
  }
}

template <class T>
inline int finish_scalar(const T* row, int x, int x1, std::uint16_t thr, RunState& s) noexcept {
  for (; x < x1; ++x) {
    const bool bright = row[x] >= thr;
    if (bright != s.in_run) {
      if (bright) {
        s.in_run = true;
        s.start = x;
      } else if (!s.emit(x)) {
        return s.count;
      }
    }
  }
  if (s.in_run) s.emit(x1);
  return s.count;
}

int runs8_scalar(const std::uint8_t* row, int x0, int x1, std::uint16_t thr, RowRun* out,
                 int cap) noexcept {
  RunState s{out, cap};
  return finish_scalar(row, x0, x1, thr, s);
}

int runs16_scalar(const std::uint16_t* row, int x0, int x1, std::uint16_t thr, RowRun* out,
                  int cap) noexcept {
  RunState s{out, cap};
  return finish_scalar(row, x0, x1, thr, s);
}

#if MOCAP_DETECT_X86
int runs8_sse2(const std::uint8_t* row, int x0, int x1, std::uint16_t thr, RowRun* out,
               int cap) noexcept {
  RunState s{out, cap};
  const __m128i t = _mm_set1_epi8(static_cast<char>(thr));
  int x = x0;
  for (; x + 16 <= x1; x += 16) {
    const __m128i v = _mm_loadu_si128(reinterpret_cast<const __m128i*>(row + x));
    const __m128i ge = _mm_cmpeq_epi8(_mm_max_epu8(v, t), v);
    const auto m = static_cast<std::uint32_t>(_mm_movemask_epi8(ge));
    if (!walk_mask(m, 16, x, s)) return s.count;
  }
  return finish_scalar(row, x, x1, thr, s);
}

int runs16_sse2(const std::uint16_t* row, int x0, int x1, std::uint16_t thr, RowRun* out,
                int cap) noexcept {
  RunState s{out, cap};
  // Unsigned v >= thr  <=>  signed (v ^ 0x8000) > ((thr - 1) ^ 0x8000), thr >= 1.
  const __m128i flip = _mm_set1_epi16(static_cast<short>(0x8000));
  const __m128i t = _mm_set1_epi16(static_cast<short>((thr - 1) ^ 0x8000));
  int x = x0;
  for (; x + 16 <= x1; x += 16) {
    const __m128i a = _mm_loadu_si128(reinterpret_cast<const __m128i*>(row + x));
    const __m128i b = _mm_loadu_si128(reinterpret_cast<const __m128i*>(row + x + 8));
    const __m128i ga = _mm_cmpgt_epi16(_mm_xor_si128(a, flip), t);
    const __m128i gb = _mm_cmpgt_epi16(_mm_xor_si128(b, flip), t);
    const auto m = static_cast<std::uint32_t>(_mm_movemask_epi8(_mm_packs_epi16(ga, gb)));
    if (!walk_mask(m, 16, x, s)) return s.count;
  }
  return finish_scalar(row, x, x1, thr, s);
}

__attribute__((target("avx2"))) int runs8_avx2(const std::uint8_t* row, int x0, int x1,
                                               std::uint16_t thr, RowRun* out, int cap) noexcept {
  RunState s{out, cap};
  const __m256i t = _mm256_set1_epi8(static_cast<char>(thr));
  int x = x0;
  // Dark fast path while no run is open: 128 pixels per test. max() folds four
  // vectors; a saturating subtract of (threshold - 1) is non-zero iff some v >= thr.
  const __m256i t_minus_1 = _mm256_set1_epi8(static_cast<char>(thr - 1));
  for (;;) {
    if (!s.in_run) {
      while (x + 128 <= x1) {
        const auto* p = reinterpret_cast<const __m256i*>(row + x);
        const __m256i mx =
            _mm256_max_epu8(_mm256_max_epu8(_mm256_loadu_si256(p), _mm256_loadu_si256(p + 1)),
                            _mm256_max_epu8(_mm256_loadu_si256(p + 2), _mm256_loadu_si256(p + 3)));
        const __m256i over = _mm256_subs_epu8(mx, t_minus_1);
        if (!_mm256_testz_si256(over, over)) break;
        x += 128;
      }
    }
    if (x + 32 > x1) break;
    const __m256i v = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(row + x));
    const __m256i ge = _mm256_cmpeq_epi8(_mm256_max_epu8(v, t), v);
    const auto m = static_cast<std::uint32_t>(_mm256_movemask_epi8(ge));
    if (!walk_mask(m, 32, x, s)) return s.count;
    x += 32;
  }
  return finish_scalar(row, x, x1, thr, s);
}

__attribute__((target("avx2"))) int runs16_avx2(const std::uint16_t* row, int x0, int x1,
                                                std::uint16_t thr, RowRun* out, int cap) noexcept {
  RunState s{out, cap};
  const __m256i t = _mm256_set1_epi16(static_cast<short>(thr));
  const __m256i t_minus_1 = _mm256_set1_epi16(static_cast<short>(thr - 1));
  int x = x0;
  for (;;) {
    if (!s.in_run) {  // dark fast path: 64 pixels per test (see runs8_avx2)
      while (x + 64 <= x1) {
        const auto* p = reinterpret_cast<const __m256i*>(row + x);
        const __m256i mx = _mm256_max_epu16(
            _mm256_max_epu16(_mm256_loadu_si256(p), _mm256_loadu_si256(p + 1)),
            _mm256_max_epu16(_mm256_loadu_si256(p + 2), _mm256_loadu_si256(p + 3)));
        const __m256i over = _mm256_subs_epu16(mx, t_minus_1);
        if (!_mm256_testz_si256(over, over)) break;
        x += 64;
      }
    }
    if (x + 32 > x1) break;
    const __m256i a = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(row + x));
    const __m256i b = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(row + x + 16));
    const __m256i ga = _mm256_cmpeq_epi16(_mm256_max_epu16(a, t), a);
    const __m256i gb = _mm256_cmpeq_epi16(_mm256_max_epu16(b, t), b);
    // packs interleaves 128-bit lanes: [a0-7 b0-7 a8-15 b8-15] -> reorder to pixel order.
    const __m256i packed = _mm256_permute4x64_epi64(_mm256_packs_epi16(ga, gb), 0xD8);
    const auto m = static_cast<std::uint32_t>(_mm256_movemask_epi8(packed));
    if (!walk_mask(m, 32, x, s)) return s.count;
    x += 32;
  }
  return finish_scalar(row, x, x1, thr, s);
}
#endif

}  // namespace

RowRunKernels select_row_run_kernels(SimdLevel requested) noexcept {
#if MOCAP_DETECT_X86
  const bool has_avx2 = __builtin_cpu_supports("avx2") != 0;
  if ((requested == SimdLevel::kAuto || requested == SimdLevel::kAvx2) && has_avx2) {
    return {runs8_avx2, runs16_avx2, SimdLevel::kAvx2};
  }
  if (requested != SimdLevel::kScalar) return {runs8_sse2, runs16_sse2, SimdLevel::kSse2};
#else
  (void)requested;
#endif
  return {runs8_scalar, runs16_scalar, SimdLevel::kScalar};
}

const char* simd_level_name(SimdLevel level) noexcept {
  switch (level) {
    case SimdLevel::kAuto:
      return "auto";
    case SimdLevel::kScalar:
      return "scalar";
    case SimdLevel::kSse2:
      return "sse2";
    case SimdLevel::kAvx2:
      return "avx2";
  }
  return "unknown";
}

}  // namespace mocap::detect
