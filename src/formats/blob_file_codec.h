// Design: the little-endian field codec, constants and CRC of the blob file
// (blob_file.h), shared by its reader (blob_file.cpp) and writer (blob_file_writer.cpp).
// Internal to src/formats: a named namespace (not anonymous), so that a unity build of the
// two files sees one definition.
#pragma once

#include <unistd.h>

#include <algorithm>
#include <bit>
#include <cerrno>
#include <cstddef>
#include <cstdint>
#include <string>

#include "client/crc32.h"

namespace mocap::blob_codec {

inline constexpr char kMagic[8] = {'M', 'O', 'C', 'A', 'P', 'B', 'L', 'B'};
inline constexpr std::uint8_t kSync[4] = {'B', 'L', 'B', 'F'};
inline constexpr std::size_t kFixedHeaderBytes = 32;
inline constexpr std::size_t kMaxRecordBytes = 4096;

inline void put16(std::uint8_t* p, std::uint16_t v) noexcept {
  p[0] = static_cast<std::uint8_t>(v);
  p[1] = static_cast<std::uint8_t>(v >> 8);
}
inline void put32(std::uint8_t* p, std::uint32_t v) noexcept {
  for (int i = 0; i < 4; ++i) p[i] = static_cast<std::uint8_t>(v >> (8 * i));
}
inline void put64(std::uint8_t* p, std::uint64_t v) noexcept {
  for (int i = 0; i < 8; ++i) p[i] = static_cast<std::uint8_t>(v >> (8 * i));
}
inline std::uint16_t get16(const std::uint8_t* p) noexcept {
  return static_cast<std::uint16_t>(p[0] | (p[1] << 8));
}
inline std::uint32_t get32(const std::uint8_t* p) noexcept {
  std::uint32_t v = 0;
  for (int i = 3; i >= 0; --i) v = (v << 8) | p[i];
  return v;
}
inline std::uint64_t get64(const std::uint8_t* p) noexcept {
  std::uint64_t v = 0;
  for (int i = 7; i >= 0; --i) v = (v << 8) | p[i];
  return v;
}
inline void putf(std::uint8_t* p, float v) noexcept { put32(p, std::bit_cast<std::uint32_t>(v)); }
inline void putd(std::uint8_t* p, double v) noexcept { put64(p, std::bit_cast<std::uint64_t>(v)); }
inline float getf(const std::uint8_t* p) noexcept { return std::bit_cast<float>(get32(p)); }
inline double getd(const std::uint8_t* p) noexcept { return std::bit_cast<double>(get64(p)); }
inline std::uint16_t box16(int v) noexcept {
  return static_cast<std::uint16_t>(std::clamp(v, 0, 65535));
}

inline std::uint32_t crc(const std::uint8_t* p, std::size_t n) noexcept {
  return client::crc32_ieee(p, n);
}

// pread all of n bytes at off; false on a short read or an error.
inline bool read_at(int fd, std::uint8_t* out, std::size_t n, std::uint64_t off) noexcept {
  while (n > 0) {
    const ssize_t r = ::pread(fd, out, n, static_cast<off_t>(off));
    if (r < 0 && errno == EINTR) continue;
    if (r <= 0) return false;
    out += r;
    n -= static_cast<std::size_t>(r);
    off += static_cast<std::uint64_t>(r);
  }
  return true;
}

inline std::string offset_text(std::uint64_t off) { return "byte offset " + std::to_string(off); }

}  // namespace mocap::blob_codec
