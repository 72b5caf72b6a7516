// Design: slicing-by-16 CRC-32 (IEEE). Table k maps a byte to its CRC contribution k bytes
// further on, so the main loop folds 16 input bytes per step with 16 independent look-ups
// (16 KiB of tables, computed at compile time);
// the tail is processed byte by byte with table 0 (the classic Sarwate algorithm).
#include "client/crc32.h"

#include <array>
#include <cstring>

namespace mocap::client {
namespace {

using Tables = std::array<std::array<std::uint32_t, 256>, 16>;

constexpr Tables make_tables() {
  Tables t{};
  for (std::uint32_t i = 0; i < 256; ++i) {
    std::uint32_t c = i;
    for (int bit = 0; bit < 8; ++bit) c = (c & 1u) ? (0xEDB88320u ^ (c >> 1)) : (c >> 1);
    t[0][i] = c;
  }
  for (std::size_t k = 1; k < 16; ++k) {
    for (std::size_t i = 0; i < 256; ++i) {
      const std::uint32_t prev = t[k - 1][i];
      t[k][i] = (prev >> 8) ^ t[0][prev & 0xFFu];
    }
  }
  return t;
}

constexpr Tables kTables = make_tables();

inline std::uint32_t load_le32(const std::uint8_t* p) noexcept {
  return static_cast<std::uint32_t>(p[0]) | (static_cast<std::uint32_t>(p[1]) << 8) |
         (static_cast<std::uint32_t>(p[2]) << 16) | (static_cast<std::uint32_t>(p[3]) << 24);
}

}  // namespace

std::uint32_t crc32_ieee(const std::uint8_t* data, std::size_t len, std::uint32_t crc) noexcept {
  std::uint32_t c = ~crc;
  if (data == nullptr) return crc;
  while (len >= 16) {
    const std::uint32_t w0 = load_le32(data) ^ c;
    const std::uint32_t w1 = load_le32(data + 4);
    const std::uint32_t w2 = load_le32(data + 8);
    const std::uint32_t w3 = load_le32(data + 12);
    c = kTables[15][w0 & 0xFFu] ^ kTables[14][(w0 >> 8) & 0xFFu] ^ kTables[13][(w0 >> 16) & 0xFFu] ^
        kTables[12][w0 >> 24] ^ kTables[11][w1 & 0xFFu] ^ kTables[10][(w1 >> 8) & 0xFFu] ^
        kTables[9][(w1 >> 16) & 0xFFu] ^ kTables[8][w1 >> 24] ^ kTables[7][w2 & 0xFFu] ^
        kTables[6][(w2 >> 8) & 0xFFu] ^ kTables[5][(w2 >> 16) & 0xFFu] ^ kTables[4][w2 >> 24] ^
        kTables[3][w3 & 0xFFu] ^ kTables[2][(w3 >> 8) & 0xFFu] ^ kTables[1][(w3 >> 16) & 0xFFu] ^
        kTables[0][w3 >> 24];
    data += 16;
    len -= 16;
  }
  while (len-- > 0) c = (c >> 8) ^ kTables[0][(c ^ *data++) & 0xFFu];
  return ~c;
}

}  // namespace mocap::client
