// Design: the spec's UDP datagram, versions 1 and 2 (docs/formats.md has the byte tables;
// version 2 = version 1's header and records, each record followed by the joint's quality
// and rates). encode_datagram/decode_datagram convert between JointsMessage and wire bytes with
// explicit little-endian packing (no struct punning, so host layout and padding never
// leak onto the wire). decode validates everything (size, magic, version, length, CRC,
// joint count, record bytes) BEFORE writing `out`: a rejected datagram leaves `out`
// untouched. Both are noexcept and allocation-free (hot path on both ends).
#pragma once

#include <cstddef>
#include <cstdint>

#include "client/joints_message.h"

namespace mocap::client {

inline constexpr std::uint16_t kDatagramVersion = 1;   // the default, unchanged
inline constexpr std::uint16_t kDatagramVersion2 = 2;  // + quality and rates per joint
inline constexpr std::size_t kDatagramHeaderBytes = 40;
inline constexpr std::size_t kJointRecordBytes = 32;    // version 1
inline constexpr std::size_t kJointRecordV2Bytes = 72;  // version 2: the v1 record + 40
inline constexpr std::size_t kDatagramCrcBytes = 4;

constexpr std::size_t joint_record_bytes(std::uint16_t version) noexcept {
  return version == kDatagramVersion2 ? kJointRecordV2Bytes : kJointRecordBytes;
}
// Bytes of a datagram of `version` (1 or 2) carrying `joint_count` records.
constexpr std::size_t datagram_size(std::size_t joint_count,
                                    std::uint16_t version = kDatagramVersion) noexcept {
  return kDatagramHeaderBytes + joint_record_bytes(version) * joint_count + kDatagramCrcBytes;
}
inline constexpr std::size_t kMinDatagramBytes = datagram_size(0);
// The largest datagram of either version (receive buffers).
inline constexpr std::size_t kMaxDatagramBytes = datagram_size(kMaxJoints, kDatagramVersion2);

enum class DecodeStatus : std::uint8_t {
  kOk = 0,
  kTooShort,       // fewer bytes than an empty datagram (44)
  kBadMagic,       // not 'M' 'C' 'A' 'P'
  kBadVersion,     // version not 1 or 2
  kBadLength,      // length != 44 + 32 J (version 1), 44 + 72 J (version 2)
  kBadCrc,         // CRC-32 mismatch
  kTooManyJoints,  // well-formed, but J > kMaxJoints: cannot be stored in JointsMessage
  kBadRecord,      // a record's type is not 0/1, a valid byte not 0/1, solved_by not 0..2
};
inline constexpr std::size_t kDecodeStatusCount = 8;

const char* to_string(DecodeStatus status) noexcept;

// Writes the datagram of `msg` in `version` (1 or 2) into buf; returns its size, or 0 when
// `cap` is too small, the version unknown or msg.joint_count > kMaxJoints.
std::size_t encode_datagram(const JointsMessage& msg, std::uint8_t* buf, std::size_t cap,
                            std::uint16_t version = kDatagramVersion) noexcept;

// Validates `len` bytes of either version and, only when kOk, fills `out` (unused records
// are reset; a version 1 datagram leaves quality and rates at their defaults) and, when
// given, *version.
DecodeStatus decode_datagram(const std::uint8_t* buf, std::size_t len, JointsMessage& out,
                             std::uint16_t* version = nullptr) noexcept;

}  // namespace mocap::client
