// Design: datagram v1 against the spec: hand-written expected bytes for a one-joint
// message, round trips for every joint count, and every corruption (each bit of each
// byte flipped, every truncation, wrong magic/version/length/CRC, J too large, bad
// record bytes) rejected with the right status, leaving the output untouched.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <random>
#include <type_traits>
#include <vector>

#include "client/crc32.h"
#include "client/datagram.h"

namespace {

using namespace mocap::client;

JointsMessage random_message(std::mt19937& rng, std::uint16_t joints) {
  std::uniform_real_distribution<float> angle(-3.14f, 3.14f);
  JointsMessage m;
  m.sequence = (static_cast<std::uint64_t>(rng()) << 32) | rng();
  m.capture_ns = static_cast<std::int64_t>(rng()) * 1000;
  m.publish_ns = m.capture_ns + 12345;
  m.flags = rng() & 1u;
  m.joint_count = joints;
  for (std::uint16_t j = 0; j < joints; ++j) {
    JointRecord& r = m.joints[j];
    r.index = j;
    r.type = static_cast<std::uint8_t>(rng() & 1u);
    r.valid = static_cast<std::uint8_t>(rng() & 1u);
    for (float& a : r.a) a = angle(rng);
    for (float& q : r.q) q = angle(rng) / 3.14f;
  }
  return m;
}

void expect_same(const JointsMessage& a, const JointsMessage& b) {
  ASSERT_EQ(a.joint_count, b.joint_count);
  EXPECT_EQ(a.sequence, b.sequence);
  EXPECT_EQ(a.capture_ns, b.capture_ns);
  EXPECT_EQ(a.publish_ns, b.publish_ns);
  EXPECT_EQ(a.flags, b.flags);
  for (std::size_t j = 0; j < a.joint_count; ++j) {
    EXPECT_EQ(a.joints[j].index, b.joints[j].index);
    EXPECT_EQ(a.joints[j].type, b.joints[j].type);
    EXPECT_EQ(a.joints[j].valid, b.joints[j].valid);
    EXPECT_EQ(0, std::memcmp(a.joints[j].a, b.joints[j].a, sizeof(a.joints[j].a)));
    EXPECT_EQ(0, std::memcmp(a.joints[j].q, b.joints[j].q, sizeof(a.joints[j].q)));
  }
}

std::vector<std::uint8_t> encode(const JointsMessage& m) {
  std::vector<std::uint8_t> buf(kMaxDatagramBytes + 64);
  buf.resize(encode_datagram(m, buf.data(), buf.size()));
  return buf;
}

void refresh_crc(std::vector<std::uint8_t>& b) {
  const std::size_t body = b.size() - 4;
  const std::uint32_t c = crc32_ieee(b.data(), body);
  for (int i = 0; i < 4; ++i)
    b[body + static_cast<std::size_t>(i)] = static_cast<std::uint8_t>(c >> (8 * i));
}

TEST(Datagram, SpecByteLayoutOfOneJointMessage) {
  JointsMessage m;
  m.sequence = 0x0102030405060708ull;
  m.capture_ns = 1000;
  m.publish_ns = 2000;
  m.flags = kFlagAllBodiesFound;
  m.joint_count = 1;
  m.joints[0].index = 3;
  m.joints[0].type = 1;
  m.joints[0].valid = 1;
  m.joints[0].a[0] = 1.0f;   // IEEE-754: 0x3F800000
  m.joints[0].a[1] = -2.0f;  // 0xC0000000
  m.joints[0].a[2] = 0.5f;   // 0x3F000000
  m.joints[0].q[0] = 1.0f;
  const std::vector<std::uint8_t> expected_body = {
      'M',  'C',  'A',  'P',  0x01, 0x00, 0x01, 0x00,  // magic, version 1, J = 1
      0x08, 0x07, 0x06, 0x05, 0x04, 0x03, 0x02, 0x01,  // sequence
      0xE8, 0x03, 0,    0,    0,    0,    0,    0,     // capture 1000 ns
      0xD0, 0x07, 0,    0,    0,    0,    0,    0,     // publish 2000 ns
      0x01, 0,    0,    0,    0,    0,    0,    0,     // flags, reserved
      0x03, 0x00, 0x01, 0x01,                          // index 3, hinge, valid
      0x00, 0x00, 0x80, 0x3F, 0x00, 0x00, 0x00, 0xC0, 0x00, 0x00, 0x00, 0x3F,  // a0 a1 a2
      0x00, 0x00, 0x80, 0x3F, 0,    0,    0,    0,    0,    0,    0,    0,
      0,    0,    0,    0,  // qw qx qy qz
  };
  const auto bytes = encode(m);
  ASSERT_EQ(bytes.size(), 40u + 32u + 4u);
  ASSERT_EQ(std::vector<std::uint8_t>(bytes.begin(), bytes.end() - 4), expected_body);
  // CRC-32 of the 72 bytes before it, little-endian, by a bitwise reference.
  std::uint32_t c = 0xFFFFFFFFu;
  for (std::uint8_t b : expected_body) {
    c ^= b;
    for (int k = 0; k < 8; ++k) c = (c >> 1) ^ (0xEDB88320u & (0u - (c & 1u)));
  }
  c = ~c;
  EXPECT_EQ(bytes[72], c & 0xFFu);
  EXPECT_EQ(bytes[73], (c >> 8) & 0xFFu);
  EXPECT_EQ(bytes[74], (c >> 16) & 0xFFu);
  EXPECT_EQ(bytes[75], c >> 24);
}

// One joint type for the project and the message (core/joint_type.h), with the spec's
// wire values.
TEST(Datagram, JointKindIsTheProjectsJointTypeWithTheWireValues) {
  static_assert(std::is_same_v<JointKind, mocap::JointType>);
  static_assert(sizeof(JointKind) == 1);
  EXPECT_EQ(static_cast<int>(JointKind::kBall), 0);
  EXPECT_EQ(static_cast<int>(JointKind::kHinge), 1);
}

TEST(Datagram, RoundTripForEveryJointCount) {
  std::mt19937 rng(1);
  for (std::uint16_t j = 0; j <= kMaxJoints; ++j) {
    for (int rep = 0; rep < 5; ++rep) {
      const JointsMessage m = random_message(rng, j);
      const auto bytes = encode(m);
      ASSERT_EQ(bytes.size(), datagram_size(j));
      JointsMessage out;
      ASSERT_EQ(decode_datagram(bytes.data(), bytes.size(), out), DecodeStatus::kOk);
      expect_same(m, out);
    }
  }
}

TEST(Datagram, NonFiniteAnglesSurviveBitExactly) {
  JointsMessage m;
  m.joint_count = 1;
  m.joints[0].a[0] = std::nanf("");
  m.joints[0].a[1] = INFINITY;
  m.joints[0].a[2] = -0.0f;
  const auto bytes = encode(m);
  JointsMessage out;
  ASSERT_EQ(decode_datagram(bytes.data(), bytes.size(), out), DecodeStatus::kOk);
  expect_same(m, out);
}

TEST(Datagram, EncodeRejectsSmallBufferAndTooManyJoints) {
  JointsMessage m;
  m.joint_count = 2;
  std::vector<std::uint8_t> buf(datagram_size(2));
  EXPECT_EQ(encode_datagram(m, buf.data(), buf.size() - 1), 0u);
  EXPECT_EQ(encode_datagram(m, buf.data(), buf.size()), buf.size());
  m.joint_count = kMaxJoints + 1;
  std::vector<std::uint8_t> big(datagram_size(kMaxJoints + 1));
  EXPECT_EQ(encode_datagram(m, big.data(), big.size()), 0u);
}

TEST(Datagram, EveryBitFlipIsRejectedAndOutputUntouched) {
  std::mt19937 rng(2);
  const JointsMessage m = random_message(rng, 3);
  const auto good = encode(m);
  JointsMessage sentinel;
  sentinel.sequence = 777;
  for (std::size_t i = 0; i < good.size(); ++i) {
    for (int bit = 0; bit < 8; ++bit) {
      auto bad = good;
      bad[i] = static_cast<std::uint8_t>(bad[i] ^ (1u << bit));
      JointsMessage out = sentinel;
      const DecodeStatus s = decode_datagram(bad.data(), bad.size(), out);
      ASSERT_NE(s, DecodeStatus::kOk) << "byte " << i << " bit " << bit;
      EXPECT_EQ(out.sequence, 777u);
      if (i < 4)
        EXPECT_EQ(s, DecodeStatus::kBadMagic);
      else if (i < 6)
        EXPECT_EQ(s, DecodeStatus::kBadVersion);
      else if (i < 8)
        EXPECT_EQ(s, DecodeStatus::kBadLength);
      else
        EXPECT_EQ(s, DecodeStatus::kBadCrc) << "byte " << i;
    }
  }
}

TEST(Datagram, EveryTruncationAndExtensionIsRejected) {
  std::mt19937 rng(3);
  const auto good = encode(random_message(rng, 4));
  JointsMessage out;
  for (std::size_t n = 0; n < good.size(); ++n) {
    const DecodeStatus s = decode_datagram(good.data(), n, out);
    EXPECT_EQ(s, n < kMinDatagramBytes ? DecodeStatus::kTooShort : DecodeStatus::kBadLength) << n;
  }
  auto longer = good;
  longer.push_back(0);
  EXPECT_EQ(decode_datagram(longer.data(), longer.size(), out), DecodeStatus::kBadLength);
  EXPECT_EQ(decode_datagram(nullptr, 100, out), DecodeStatus::kTooShort);
}

TEST(Datagram, WrongFieldsWithValidCrcGiveTheirStatus) {
  std::mt19937 rng(4);
  const auto good = encode(random_message(rng, 2));
  JointsMessage out;
  auto bad = good;
  bad[0] = 'X';
  refresh_crc(bad);
  EXPECT_EQ(decode_datagram(bad.data(), bad.size(), out), DecodeStatus::kBadMagic);
  bad = good;
  bad[4] = 3;
  refresh_crc(bad);
  EXPECT_EQ(decode_datagram(bad.data(), bad.size(), out), DecodeStatus::kBadVersion);
  bad = good;
  bad[4] = 2;  // version 2 records are 72 bytes: these do not fit
  refresh_crc(bad);
  EXPECT_EQ(decode_datagram(bad.data(), bad.size(), out), DecodeStatus::kBadLength);
  bad = good;
  bad[6] = 3;  // J = 3 but 2 records
  refresh_crc(bad);
  EXPECT_EQ(decode_datagram(bad.data(), bad.size(), out), DecodeStatus::kBadLength);
  bad = good;
  bad[bad.size() - 1] ^= 0x55;
  EXPECT_EQ(decode_datagram(bad.data(), bad.size(), out), DecodeStatus::kBadCrc);
  bad = good;
  bad[40 + 2] = 2;  // joint type 2 does not exist
  refresh_crc(bad);
  EXPECT_EQ(decode_datagram(bad.data(), bad.size(), out), DecodeStatus::kBadRecord);
  bad = good;
  bad[40 + 32 + 3] = 7;  // valid byte of the second record
  refresh_crc(bad);
  EXPECT_EQ(decode_datagram(bad.data(), bad.size(), out), DecodeStatus::kBadRecord);
}

TEST(Datagram, WellFormedDatagramWithTooManyJointsIsRejected) {
  const std::uint16_t j = kMaxJoints + 1;
  std::vector<std::uint8_t> b(datagram_size(j), 0);
  std::memcpy(b.data(), "MCAP", 4);
  b[4] = 1;
  b[6] = static_cast<std::uint8_t>(j);
  refresh_crc(b);
  JointsMessage out;
  EXPECT_EQ(decode_datagram(b.data(), b.size(), out), DecodeStatus::kTooManyJoints);
  EXPECT_STREQ(to_string(DecodeStatus::kTooManyJoints), "too many joints");
}

TEST(Datagram, HostileRandomBytesNeverDecodeOrCrash) {
  std::mt19937 rng(5);
  std::vector<std::uint8_t> b(kMaxDatagramBytes + 100);
  JointsMessage out;
  int ok = 0;
  for (int trial = 0; trial < 20000; ++trial) {
    const std::size_t n = rng() % b.size();
    for (std::size_t i = 0; i < n; ++i) b[i] = static_cast<std::uint8_t>(rng());
    if (trial % 2 == 0 && n >= 8) {  // plausible header, random rest
      std::memcpy(b.data(), "MCAP", 4);
      b[4] = 1;
      b[5] = 0;
    }
    if (decode_datagram(b.data(), n, out) == DecodeStatus::kOk) ++ok;
  }
  EXPECT_EQ(ok, 0);
}

}  // namespace
