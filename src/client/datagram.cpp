// Design: byte-exact little-endian packing of datagrams v1 and v2. Header integers are
// packed byte by byte; the 32-byte joint records are copied whole (their in-memory layout
// is the wire layout, checked at compile time), the v2 tail field by field, so floats
// travel as their exact IEEE-754 bit patterns. Validation order: size, magic, version,
// length (from J), CRC, joint count, record bytes; `out` is written only after every check
// passed.
#include "client/datagram.h"

#include <bit>
#include <cstddef>
#include <cstring>

#include "client/crc32.h"

namespace mocap::client {
namespace {

constexpr std::uint8_t kMagic[4] = {'M', 'C', 'A', 'P'};

// A JointRecord in memory IS the 32-byte wire record on little-endian hosts (same offsets,
// no padding), so records are copied whole. Every supported target (x86-64, ARM64) is
// little-endian; a big-endian port would need per-field packing of the records.
static_assert(std::endian::native == std::endian::little,
              "datagram v1 codec assumes little-endian");
static_assert(sizeof(JointRecord) == 32 && offsetof(JointRecord, index) == 0 &&
                  offsetof(JointRecord, type) == 2 && offsetof(JointRecord, valid) == 3 &&
                  offsetof(JointRecord, a) == 4 && offsetof(JointRecord, q) == 16,
              "JointRecord must match the wire record layout");

inline void put_u16(std::uint8_t* p, std::uint16_t v) noexcept {
  p[0] = static_cast<std::uint8_t>(v & 0xFFu);
  p[1] = static_cast<std::uint8_t>(v >> 8);
}
inline void put_u32(std::uint8_t* p, std::uint32_t v) noexcept {
  for (int i = 0; i < 4; ++i) p[i] = static_cast<std::uint8_t>((v >> (8 * i)) & 0xFFu);
}
inline void put_u64(std::uint8_t* p, std::uint64_t v) noexcept {
  for (int i = 0; i < 8; ++i) p[i] = static_cast<std::uint8_t>((v >> (8 * i)) & 0xFFu);
}

inline void put_f32(std::uint8_t* p, float v) noexcept {
  put_u32(p, std::bit_cast<std::uint32_t>(v));
}

inline std::uint16_t get_u16(const std::uint8_t* p) noexcept {
  return static_cast<std::uint16_t>(p[0] | (p[1] << 8));
}
inline std::uint32_t get_u32(const std::uint8_t* p) noexcept {
  std::uint32_t v = 0;
  for (int i = 3; i >= 0; --i) v = (v << 8) | p[i];
  return v;
}
inline std::uint64_t get_u64(const std::uint8_t* p) noexcept {
  std::uint64_t v = 0;
  for (int i = 7; i >= 0; --i) v = (v << 8) | p[i];
  return v;
}

inline float get_f32(const std::uint8_t* p) noexcept { return std::bit_cast<float>(get_u32(p)); }

// The 40 bytes a v2 record adds after the v1 record (docs/formats.md).
void put_v2_tail(std::uint8_t* p, const JointQuality& q, const JointRates& r) noexcept {
  p[0] = q.solved_by;
  p[1] = r.valid;
  p[2] = p[3] = 0;
  for (int k = 0; k < 3; ++k) {
    put_f32(p + 4 + 4 * k, q.sd_rad[k]);
    put_f32(p + 16 + 4 * k, r.rate_rad_s[k]);
    put_f32(p + 28 + 4 * k, r.sd_rad_s[k]);
  }
}

void get_v2_tail(const std::uint8_t* p, JointQuality& q, JointRates& r) noexcept {
  q = JointQuality{};
  r = JointRates{};
  q.solved_by = p[0];
  r.valid = p[1];
  for (int k = 0; k < 3; ++k) {
    q.sd_rad[k] = get_f32(p + 4 + 4 * k);
    r.rate_rad_s[k] = get_f32(p + 16 + 4 * k);
    r.sd_rad_s[k] = get_f32(p + 28 + 4 * k);
  }
}

}  // namespace

const char* to_string(DecodeStatus status) noexcept {
  switch (status) {
    case DecodeStatus::kOk:
      return "ok";
    case DecodeStatus::kTooShort:
      return "too short";
    case DecodeStatus::kBadMagic:
      return "bad magic";
    case DecodeStatus::kBadVersion:
      return "bad version";
    case DecodeStatus::kBadLength:
      return "bad length";
    case DecodeStatus::kBadCrc:
      return "bad crc";
    case DecodeStatus::kTooManyJoints:
      return "too many joints";
    case DecodeStatus::kBadRecord:
      return "bad record";
  }
  return "unknown";
}

std::size_t encode_datagram(const JointsMessage& msg, std::uint8_t* buf, std::size_t cap,
                            std::uint16_t version) noexcept {
  if (msg.joint_count > kMaxJoints || buf == nullptr) return 0;
  if (version != kDatagramVersion && version != kDatagramVersion2) return 0;
  const std::size_t size = datagram_size(msg.joint_count, version);
  if (cap < size) return 0;
  for (int i = 0; i < 4; ++i) buf[i] = kMagic[i];
  put_u16(buf + 4, version);
  put_u16(buf + 6, msg.joint_count);
  put_u64(buf + 8, msg.sequence);
  put_u64(buf + 16, static_cast<std::uint64_t>(msg.capture_ns));
  put_u64(buf + 24, static_cast<std::uint64_t>(msg.publish_ns));
  put_u32(buf + 32, msg.flags);
  put_u32(buf + 36, (msg.flags & kFlagPredicted) != 0 ? msg.lead_us : 0u);
  std::uint8_t* r = buf + kDatagramHeaderBytes;
  if (version == kDatagramVersion) {
    std::memcpy(r, msg.joints, kJointRecordBytes * msg.joint_count);
  } else {
    for (std::size_t j = 0; j < msg.joint_count; ++j, r += kJointRecordV2Bytes) {
      std::memcpy(r, &msg.joints[j], kJointRecordBytes);
      put_v2_tail(r + kJointRecordBytes, msg.quality[j], msg.rates[j]);
    }
  }
  put_u32(buf + size - kDatagramCrcBytes, crc32_ieee(buf, size - kDatagramCrcBytes));
  return size;
}

DecodeStatus decode_datagram(const std::uint8_t* buf, std::size_t len, JointsMessage& out,
                             std::uint16_t* version_out) noexcept {
  if (buf == nullptr || len < kMinDatagramBytes) return DecodeStatus::kTooShort;
  for (int i = 0; i < 4; ++i) {
    if (buf[i] != kMagic[i]) return DecodeStatus::kBadMagic;
  }
  const std::uint16_t version = get_u16(buf + 4);
  if (version != kDatagramVersion && version != kDatagramVersion2) return DecodeStatus::kBadVersion;
  const std::uint16_t joint_count = get_u16(buf + 6);
  if (len != datagram_size(joint_count, version)) return DecodeStatus::kBadLength;
  const std::size_t record_bytes = joint_record_bytes(version);
  const std::size_t body = len - kDatagramCrcBytes;
  if (crc32_ieee(buf, body) != get_u32(buf + body)) return DecodeStatus::kBadCrc;
  if (joint_count > kMaxJoints) return DecodeStatus::kTooManyJoints;
  const std::uint8_t* r = buf + kDatagramHeaderBytes;
  for (std::size_t j = 0; j < joint_count; ++j, r += record_bytes) {
    if (r[2] > static_cast<std::uint8_t>(JointKind::kHinge) || r[3] > 1) {
      return DecodeStatus::kBadRecord;
    }
    if (version == kDatagramVersion2 &&
        (r[32] > static_cast<std::uint8_t>(SolvedBy::kChain) || r[33] > 1)) {
      return DecodeStatus::kBadRecord;
    }
  }
  out.sequence = get_u64(buf + 8);
  out.capture_ns = static_cast<std::int64_t>(get_u64(buf + 16));
  out.publish_ns = static_cast<std::int64_t>(get_u64(buf + 24));
  out.flags = get_u32(buf + 32);
  out.joint_count = joint_count;
  // The lead of a predicted message (the reserved field of datagrams before 2027-01, 0).
  const std::uint32_t lead_us = get_u32(buf + 36);
  out.lead_us = (out.flags & kFlagPredicted) != 0 && lead_us <= 0xFFFFu
                    ? static_cast<std::uint16_t>(lead_us)
                    : std::uint16_t{0};
  r = buf + kDatagramHeaderBytes;
  for (std::size_t j = 0; j < joint_count; ++j, r += record_bytes) {
    std::memcpy(&out.joints[j], r, kJointRecordBytes);
    if (version == kDatagramVersion2) {
      get_v2_tail(r + kJointRecordBytes, out.quality[j], out.rates[j]);
    } else {
      out.quality[j] = JointQuality{};
      out.rates[j] = JointRates{};
    }
  }
  for (std::size_t j = joint_count; j < kMaxJoints; ++j) {
    out.joints[j] = JointRecord{};
    out.quality[j] = JointQuality{};
    out.rates[j] = JointRates{};
  }
  if (version_out != nullptr) *version_out = version;
  return DecodeStatus::kOk;
}

}  // namespace mocap::client
