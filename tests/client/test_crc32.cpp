// Design: CRC-32 against published check values, a bit-by-bit reference, zlib's crc32
// (when available) over random buffers of every length 0..300, and continuation.
#include <gtest/gtest.h>

#include <cstring>
#include <random>
#include <vector>

#include "client/crc32.h"

#ifdef MOCAP_TEST_HAVE_ZLIB
#include <zlib.h>
#endif

namespace {

using mocap::client::crc32_ieee;

std::uint32_t crc_bitwise(const std::uint8_t* p, std::size_t n) {
  std::uint32_t c = 0xFFFFFFFFu;
  for (std::size_t i = 0; i < n; ++i) {
    c ^= p[i];
    for (int b = 0; b < 8; ++b) c = (c >> 1) ^ (0xEDB88320u & (0u - (c & 1u)));
  }
  return ~c;
}

std::uint32_t crc_of(const char* s) {
  return crc32_ieee(reinterpret_cast<const std::uint8_t*>(s), std::strlen(s));
}

TEST(Crc32, KnownCheckValues) {
  EXPECT_EQ(crc_of("123456789"), 0xCBF43926u);
  EXPECT_EQ(crc_of("The quick brown fox jumps over the lazy dog"), 0x414FA339u);
  EXPECT_EQ(crc_of("a"), 0xE8B7BE43u);
  EXPECT_EQ(crc32_ieee(nullptr, 0), 0u);
}

TEST(Crc32, MatchesBitwiseReferenceAtEveryLengthAndAlignment) {
  std::mt19937 rng(7);
  std::vector<std::uint8_t> buf(320);
  for (auto& b : buf) b = static_cast<std::uint8_t>(rng());
  for (std::size_t offset = 0; offset < 8; ++offset) {
    for (std::size_t n = 0; n + offset <= 300; ++n) {
      ASSERT_EQ(crc32_ieee(buf.data() + offset, n), crc_bitwise(buf.data() + offset, n))
          << "offset " << offset << " length " << n;
    }
  }
}

TEST(Crc32, ContinuationEqualsWholeBuffer) {
  std::vector<std::uint8_t> buf(1000);
  for (std::size_t i = 0; i < buf.size(); ++i) buf[i] = static_cast<std::uint8_t>(i * 31u + 7u);
  const std::uint32_t whole = crc32_ieee(buf.data(), buf.size());
  for (std::size_t split : {0u, 1u, 7u, 8u, 9u, 500u, 999u, 1000u}) {
    const std::uint32_t first = crc32_ieee(buf.data(), split);
    EXPECT_EQ(crc32_ieee(buf.data() + split, buf.size() - split, first), whole) << split;
  }
}

#ifdef MOCAP_TEST_HAVE_ZLIB
TEST(Crc32, MatchesZlib) {
  std::mt19937 rng(11);
  std::vector<std::uint8_t> buf(2000);
  for (auto& b : buf) b = static_cast<std::uint8_t>(rng());
  for (std::size_t n = 0; n <= buf.size(); n += (n < 300 ? 1 : 37)) {
    const uLong z = ::crc32(::crc32(0L, Z_NULL, 0), buf.data(), static_cast<uInt>(n));
    ASSERT_EQ(crc32_ieee(buf.data(), n), static_cast<std::uint32_t>(z)) << n;
  }
}
#endif

}  // namespace
