// Design: CRC-32 with the IEEE 802.3 polynomial (reflected 0xEDB88320, init and final
// xor 0xFFFFFFFF), bit-identical to zlib's crc32(): the datagram v1 checksum. Slicing-by-8
// over tables computed at compile time; no dependency, noexcept, no allocation.
#pragma once

#include <cstddef>
#include <cstdint>

namespace mocap::client {

// CRC of `len` bytes. Pass the previous result as `crc` to continue over split buffers
// (crc32_ieee(b, n2, crc32_ieee(a, n1)) == crc32_ieee(a||b)), exactly like zlib.
std::uint32_t crc32_ieee(const std::uint8_t* data, std::size_t len, std::uint32_t crc = 0) noexcept;

}  // namespace mocap::client
