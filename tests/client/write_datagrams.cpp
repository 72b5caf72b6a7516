// Test tool for the independent Python decoder (decode_datagram.py): writes datagrams
// produced by OUR encoder (client::encode_datagram) and, separately, the message fields
// they were encoded from, so that a decoder written from the spec alone can check every
// field. Messages vary everything the format carries: 0..32 joints, both joint types,
// valid 0/1, negative and large timestamps, 64-bit sequence numbers, flags, float
// values including negative zero, subnormals and extremes.
//   write_datagrams DATAGRAMS_FILE EXPECTED_FILE [COUNT=200]
// DATAGRAMS_FILE: for each datagram, uint32 little-endian length, then the bytes.
// EXPECTED_FILE: one line per datagram:
//   seq capture_ns publish_ns flags J {index type valid a0 a1 a2 qw qx qy qz} x J
// (floats as %.9g: exact float32 round trip).
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <random>
#include <vector>

#include "client/datagram.h"
#include "client/joints_message.h"

namespace {

using mocap::client::JointsMessage;

float pick_float(std::mt19937_64& rng) {
  static const float special[] = {0.0f,
                                  -0.0f,
                                  1.0f,
                                  -3.14159265f,
                                  std::numeric_limits<float>::denorm_min(),
                                  std::numeric_limits<float>::max(),
                                  std::numeric_limits<float>::lowest(),
                                  1e-20f};
  if (rng() % 8 == 0) return special[rng() % (sizeof special / sizeof special[0])];
  std::uniform_real_distribution<float> u(-4.0f, 4.0f);
  return u(rng);
}

JointsMessage make_message(std::mt19937_64& rng, int i) {
  JointsMessage m;
  m.sequence = i == 1 ? std::numeric_limits<std::uint64_t>::max() : rng();
  m.capture_ns = i == 2 ? -1 : static_cast<std::int64_t>(rng() >> 1);
  m.publish_ns = static_cast<std::int64_t>(rng() >> 1);
  m.flags = static_cast<std::uint32_t>(rng() & 0x3);
  m.joint_count =
      static_cast<std::uint16_t>(i == 0 ? 0 : (i == 3 ? mocap::client::kMaxJoints : rng() % 9));
  for (std::uint16_t j = 0; j < m.joint_count; ++j) {
    mocap::client::JointRecord& r = m.joints[j];
    r.index = static_cast<std::uint16_t>(i == 4 ? 65535 : rng() % 40);
    r.type = static_cast<std::uint8_t>(rng() % 2);
    r.valid = static_cast<std::uint8_t>(rng() % 2);
    for (float& a : r.a) a = pick_float(rng);
    for (float& q : r.q) q = pick_float(rng);
  }
  return m;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 3) {
    std::fprintf(stderr, "usage: %s DATAGRAMS_FILE EXPECTED_FILE [COUNT=200]\n", argv[0]);
    return 2;
  }
  const int count = argc > 3 ? std::atoi(argv[3]) : 200;
  std::FILE* bin = std::fopen(argv[1], "wb");
  std::FILE* txt = std::fopen(argv[2], "w");
  if (bin == nullptr || txt == nullptr) {
    std::fprintf(stderr, "write_datagrams: cannot open the output files\n");
    return 1;
  }
  std::mt19937_64 rng(20240601);
  std::vector<std::uint8_t> buf(mocap::client::kMaxDatagramBytes);
  for (int i = 0; i < count; ++i) {
    const JointsMessage m = make_message(rng, i);
    const std::size_t n = mocap::client::encode_datagram(m, buf.data(), buf.size());
    if (n == 0) {
      std::fprintf(stderr, "write_datagrams: encode failed for message %d\n", i);
      return 1;
    }
    const auto len = static_cast<std::uint32_t>(n);
    const std::uint8_t le[4] = {static_cast<std::uint8_t>(len), static_cast<std::uint8_t>(len >> 8),
                                static_cast<std::uint8_t>(len >> 16),
                                static_cast<std::uint8_t>(len >> 24)};
    std::fwrite(le, 1, 4, bin);
    std::fwrite(buf.data(), 1, n, bin);
    std::fprintf(txt, "%llu %lld %lld %u %u", static_cast<unsigned long long>(m.sequence),
                 static_cast<long long>(m.capture_ns), static_cast<long long>(m.publish_ns),
                 static_cast<unsigned>(m.flags), static_cast<unsigned>(m.joint_count));
    for (std::uint16_t j = 0; j < m.joint_count; ++j) {
      const mocap::client::JointRecord& r = m.joints[j];
      std::fprintf(txt, " %u %u %u", static_cast<unsigned>(r.index), static_cast<unsigned>(r.type),
                   static_cast<unsigned>(r.valid));
      for (float a : r.a) std::fprintf(txt, " %.9g", static_cast<double>(a));
      for (float q : r.q) std::fprintf(txt, " %.9g", static_cast<double>(q));
    }
    std::fprintf(txt, "\n");
  }
  const bool ok = std::fclose(bin) == 0 && std::fclose(txt) == 0;
  return ok ? 0 : 1;
}
