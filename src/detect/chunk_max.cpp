// Design: see chunk_max.h. The AVX2 kernels fold a chunk's four 32-byte vectors with
// max, then reduce two chunks at once: the 128-bit halves of both are combined into
// one vector (chunk a in the low lane, b in the high lane) and folded within each lane
// by byte shifts, so lane element 0 holds each chunk's maximum. A row tail shorter
// than a chunk is read 32 bytes at a time and finished in scalar code; no load reaches
// past x1. The AVX2 code is compiled with a function target attribute and only called
// after a CPU check.
#include "detect/chunk_max.h"

#include <algorithm>

#if defined(__x86_64__) || defined(__i386__)
#include <immintrin.h>
#define MOCAP_CHUNK_MAX_X86 1
#endif

namespace mocap::detect {
namespace {

template <class T, int kChunk>
std::uint16_t cm_scalar(const T* row, int x0, int x1, std::uint16_t* out) noexcept {
  std::uint16_t row_max = 0;
  for (int x = x0; x < x1; x += kChunk) {
    const int end = std::min(x + kChunk, x1);
    T m = 0;
    for (int i = x; i < end; ++i) m = std::max(m, row[i]);
    *out++ = m;
    row_max = std::max<std::uint16_t>(row_max, m);
  }
  return row_max;
}

std::uint16_t cm8_scalar(const std::uint8_t* row, int x0, int x1, std::uint16_t* out) noexcept {
  return cm_scalar<std::uint8_t, kChunkPx8>(row, x0, x1, out);
}

std::uint16_t cm16_scalar(const std::uint16_t* row, int x0, int x1, std::uint16_t* out) noexcept {
  return cm_scalar<std::uint16_t, kChunkPx16>(row, x0, x1, out);
}

#if MOCAP_CHUNK_MAX_X86
// Maximum of the 128 bytes at p (unsigned 8- or 16-bit elements).
__attribute__((target("avx2"))) inline __m256i cm_fold8(const std::uint8_t* p) noexcept {
  const auto* v = reinterpret_cast<const __m256i*>(p);
  return _mm256_max_epu8(_mm256_max_epu8(_mm256_loadu_si256(v), _mm256_loadu_si256(v + 1)),
                         _mm256_max_epu8(_mm256_loadu_si256(v + 2), _mm256_loadu_si256(v + 3)));
}

__attribute__((target("avx2"))) inline __m256i cm_fold16(const std::uint16_t* p) noexcept {
  const auto* v = reinterpret_cast<const __m256i*>(p);
  return _mm256_max_epu16(_mm256_max_epu16(_mm256_loadu_si256(v), _mm256_loadu_si256(v + 1)),
                          _mm256_max_epu16(_mm256_loadu_si256(v + 2), _mm256_loadu_si256(v + 3)));
}

// Lane-wise halves of a and b: chunk a's 16 bytes in the low lane, b's in the high one.
__attribute__((target("avx2"))) inline __m256i cm_pair(__m256i a, __m256i b, bool wide) noexcept {
  const __m256i lo = _mm256_permute2x128_si256(a, b, 0x20);
  const __m256i hi = _mm256_permute2x128_si256(a, b, 0x31);
  return wide ? _mm256_max_epu16(lo, hi) : _mm256_max_epu8(lo, hi);
}

__attribute__((target("avx2"))) std::uint16_t cm8_avx2(const std::uint8_t* row, int x0, int x1,
                                                       std::uint16_t* out) noexcept {
  std::uint16_t* const first = out;
  int x = x0;
  for (; x + 2 * kChunkPx8 <= x1; x += 2 * kChunkPx8) {
    __m256i h = cm_pair(cm_fold8(row + x), cm_fold8(row + x + kChunkPx8), false);
    h = _mm256_max_epu8(h, _mm256_srli_si256(h, 8));
    h = _mm256_max_epu8(h, _mm256_srli_si256(h, 4));
    h = _mm256_max_epu8(h, _mm256_srli_si256(h, 2));
    h = _mm256_max_epu8(h, _mm256_srli_si256(h, 1));
    out[0] = static_cast<std::uint16_t>(_mm256_extract_epi8(h, 0) & 0xFF);
    out[1] = static_cast<std::uint16_t>(_mm256_extract_epi8(h, 16) & 0xFF);
    out += 2;
  }
  // The last one or two (possibly short) chunks: 32 pixels per load, then scalar.
  while (x < x1) {
    const int end = std::min(x + kChunkPx8, x1);
    __m256i m = _mm256_setzero_si256();
    for (; x + 32 <= end; x += 32) {
      m = _mm256_max_epu8(m, _mm256_loadu_si256(reinterpret_cast<const __m256i*>(row + x)));
    }
    __m128i t = _mm_max_epu8(_mm256_castsi256_si128(m), _mm256_extracti128_si256(m, 1));
    t = _mm_max_epu8(t, _mm_srli_si128(t, 8));
    t = _mm_max_epu8(t, _mm_srli_si128(t, 4));
    t = _mm_max_epu8(t, _mm_srli_si128(t, 2));
    t = _mm_max_epu8(t, _mm_srli_si128(t, 1));
    auto best = static_cast<std::uint8_t>(_mm_cvtsi128_si32(t) & 0xFF);
    for (; x < end; ++x) best = std::max(best, row[x]);
    *out++ = best;
  }
  return *std::max_element(first, out);
}

__attribute__((target("avx2"))) std::uint16_t cm16_avx2(const std::uint16_t* row, int x0, int x1,
                                                        std::uint16_t* out) noexcept {
  std::uint16_t* const first = out;
  int x = x0;
  for (; x + 2 * kChunkPx16 <= x1; x += 2 * kChunkPx16) {
    __m256i h = cm_pair(cm_fold16(row + x), cm_fold16(row + x + kChunkPx16), true);
    h = _mm256_max_epu16(h, _mm256_srli_si256(h, 8));
    h = _mm256_max_epu16(h, _mm256_srli_si256(h, 4));
    h = _mm256_max_epu16(h, _mm256_srli_si256(h, 2));
    out[0] = static_cast<std::uint16_t>(_mm256_extract_epi16(h, 0) & 0xFFFF);
    out[1] = static_cast<std::uint16_t>(_mm256_extract_epi16(h, 8) & 0xFFFF);
    out += 2;
  }
  // The last one or two (possibly short) chunks: 16 pixels per load, then scalar.
  while (x < x1) {
    const int end = std::min(x + kChunkPx16, x1);
    __m256i m = _mm256_setzero_si256();
    for (; x + 16 <= end; x += 16) {
      m = _mm256_max_epu16(m, _mm256_loadu_si256(reinterpret_cast<const __m256i*>(row + x)));
    }
    __m128i t = _mm_max_epu16(_mm256_castsi256_si128(m), _mm256_extracti128_si256(m, 1));
    t = _mm_max_epu16(t, _mm_srli_si128(t, 8));
    t = _mm_max_epu16(t, _mm_srli_si128(t, 4));
    t = _mm_max_epu16(t, _mm_srli_si128(t, 2));
    auto best = static_cast<std::uint16_t>(_mm_cvtsi128_si32(t) & 0xFFFF);
    for (; x < end; ++x) best = std::max(best, row[x]);
    *out++ = best;
  }
  return *std::max_element(first, out);
}
#endif

}  // namespace

ChunkMaxKernels select_chunk_max_kernels(SimdLevel requested) noexcept {
#if MOCAP_CHUNK_MAX_X86
  if ((requested == SimdLevel::kAuto || requested == SimdLevel::kAvx2) &&
      __builtin_cpu_supports("avx2") != 0) {
    return {cm8_avx2, cm16_avx2};
  }
#else
  (void)requested;
#endif
  return {cm8_scalar, cm16_scalar};
}

}  // namespace mocap::detect
