// Design: the spec's UDP datagram, version 1 (docs/client.md has the byte table).
// encode_datagram/decode_datagram convert between JointsMessage and wire bytes with
// explicit little-endian packing (no struct punning, so host layout and padding never
// leak onto the wire). decode validates everything (size, magic, version, length, CRC,
// joint count, record bytes) BEFORE writing `out`: a rejected datagram leaves `out`
// untouched. Both are noexcept and allocation-free (hot path on both ends).
#pragma once

#include <cstddef>
#include <cstdint>

#include "client/joints_message.h"

namespace mocap::client {

inline constexpr std::uint16_t kDatagramVersion = 1;
inline constexpr std::size_t kDatagramHeaderBytes = 40;
inline constexpr std::size_t kJointRecordBytes = 32;
inline constexpr std::size_t kDatagramCrcBytes = 4;

// Bytes of a v1 datagram carrying `joint_count` records.
constexpr std::size_t datagram_size(std::size_t joint_count) noexcept {
  return kDatagramHeaderBytes + kJointRecordBytes * joint_count + kDatagramCrcBytes;
}
inline constexpr std::size_t kMinDatagramBytes = datagram_size(0);
inline constexpr std::size_t kMaxDatagramBytes = datagram_size(kMaxJoints);

enum class DecodeStatus : std::uint8_t {
  kOk = 0,
  kTooShort,       // fewer bytes than an empty datagram (44)
  kBadMagic,       // not 'M' 'C' 'A' 'P'
  kBadVersion,     // version != 1
  kBadLength,      // length != 44 + 32 J
  kBadCrc,         // CRC-32 mismatch
  kTooManyJoints,  // well-formed, but J > kMaxJoints: cannot be stored in JointsMessage
  kBadRecord,      // extension: a record's type is not 0/1 or its valid byte not 0/1
};
inline constexpr std::size_t kDecodeStatusCount = 8;

const char* to_string(DecodeStatus status) noexcept;

// Writes the datagram of `msg` into buf; returns its size, or 0 when `cap` is too small
// or msg.joint_count > kMaxJoints.
std::size_t encode_datagram(const JointsMessage& msg, std::uint8_t* buf, std::size_t cap) noexcept;

// Validates `len` bytes and, only when kOk, fills `out` (unused records are reset).
DecodeStatus decode_datagram(const std::uint8_t* buf, std::size_t len, JointsMessage& out) noexcept;

}  // namespace mocap::client
