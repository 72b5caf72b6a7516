// Design: fuzz entry point of the client library's UDP datagram decoder. The first byte
// selects a mode so that the fuzzer also gets past the CRC: mode bit 0 set means "fix
// the CRC of the remaining bytes before decoding" (exercises the length, joint-count and
// record checks behind it). Properties: a rejected datagram leaves the output untouched;
// an accepted one re-encodes to a datagram that decodes to the same message.
#include <cstring>
#include <vector>

#include "client/crc32.h"
#include "client/datagram.h"
#include "tests/fuzz/fuzz_targets.h"

namespace mocap::fuzz {

int fuzz_datagram(const std::uint8_t* data, std::size_t size) {
  using namespace mocap::client;
  if (size == 0) return 0;
  const bool fix_crc = (data[0] & 1u) != 0;
  std::vector<std::uint8_t> buf(data + 1, data + size);
  if (fix_crc && buf.size() >= kDatagramCrcBytes) {
    const std::size_t body = buf.size() - kDatagramCrcBytes;
    const std::uint32_t crc = crc32_ieee(buf.data(), body);
    for (int i = 0; i < 4; ++i)
      buf[body + static_cast<std::size_t>(i)] = static_cast<std::uint8_t>(crc >> (8 * i));
  }
  JointsMessage out;  // a sentinel: every field set to a value no decode would write
  out.sequence = 0xA5A5A5A5A5A5A5A5ull;
  out.capture_ns = -1;
  out.publish_ns = -2;
  out.flags = 0xA5A5A5A5u;
  out.joint_count = 0xA5A5;
  out.lead_us = 0xA5A5;
  for (JointRecord& j : out.joints) j.index = 0xA5A5;
  const JointsMessage untouched = out;
  std::uint16_t version = 0;
  const DecodeStatus st = decode_datagram(buf.data(), buf.size(), out, &version);
  fuzz_check(to_string(st) != nullptr, "status without a name");
  if (st != DecodeStatus::kOk) {
    fuzz_check(out.sequence == untouched.sequence && out.capture_ns == untouched.capture_ns &&
                   out.publish_ns == untouched.publish_ns && out.flags == untouched.flags &&
                   out.joint_count == untouched.joint_count && out.lead_us == untouched.lead_us &&
                   std::memcmp(out.joints, untouched.joints, sizeof out.joints) == 0,
               "rejected datagram modified the output");
    return 0;
  }
  fuzz_check(version == kDatagramVersion || version == kDatagramVersion2, "accepted a version");
  fuzz_check(buf.size() == datagram_size(out.joint_count, version),
             "accepted a datagram of the wrong length");
  fuzz_check(out.joint_count <= kMaxJoints, "accepted too many joints");
  std::uint8_t again[kMaxDatagramBytes];
  const std::size_t n = encode_datagram(out, again, sizeof again, version);
  fuzz_check(n == buf.size(), "re-encoded size differs");
  JointsMessage back;
  fuzz_check(decode_datagram(again, n, back) == DecodeStatus::kOk, "re-encoded datagram rejected");
  fuzz_check(back.sequence == out.sequence && back.capture_ns == out.capture_ns &&
                 back.publish_ns == out.publish_ns && back.flags == out.flags &&
                 back.joint_count == out.joint_count,
             "round trip changed the header");
  fuzz_check(std::memcmp(back.joints, out.joints, sizeof out.joints) == 0,
             "round trip changed the joints");
  fuzz_check(std::memcmp(back.quality, out.quality, sizeof out.quality) == 0 &&
                 std::memcmp(back.rates, out.rates, sizeof out.rates) == 0,
             "round trip changed the quality or the rates");
  return 0;
}

}  // namespace mocap::fuzz
