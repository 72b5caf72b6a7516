// Design: datagram v2 (the 2027-01 extension: each record followed by the joint's quality
// and rates) against docs/formats.md: hand-written expected bytes of a one-joint message,
// round trips for every joint count, v1 leaving quality and rates at their defaults,
// every corruption of a v2 datagram rejected with the output untouched, and the version
// of a datagram reported.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <random>
#include <vector>

#include "client/crc32.h"
#include "client/datagram.h"

namespace {

using namespace mocap::client;

JointsMessage random_v2_message(std::mt19937& rng, std::uint16_t joints) {
  std::uniform_real_distribution<float> value(-3.0f, 3.0f);
  JointsMessage m;
  m.sequence = rng();
  m.capture_ns = static_cast<std::int64_t>(rng()) * 1000;
  m.publish_ns = m.capture_ns + 777;
  m.flags = rng() & 1u;
  m.joint_count = joints;
  for (std::uint16_t j = 0; j < joints; ++j) {
    JointRecord& r = m.joints[j];
    r.index = j;
    r.type = static_cast<std::uint8_t>(rng() & 1u);
    r.valid = static_cast<std::uint8_t>(rng() & 1u);
    for (float& a : r.a) a = value(rng);
    for (float& q : r.q) q = value(rng) / 3.0f;
    m.quality[j].solved_by = static_cast<std::uint8_t>(rng() % 3u);
    for (float& s : m.quality[j].sd_rad) s = std::abs(value(rng)) * 0.01f;
    m.rates[j].valid = static_cast<std::uint8_t>(rng() & 1u);
    for (float& d : m.rates[j].rate_rad_s) d = value(rng) * 2.0f;
    for (float& s : m.rates[j].sd_rad_s) s = std::abs(value(rng)) * 0.1f;
  }
  return m;
}

std::vector<std::uint8_t> encode(const JointsMessage& m, std::uint16_t version) {
  std::vector<std::uint8_t> buf(kMaxDatagramBytes + 64);
  buf.resize(encode_datagram(m, buf.data(), buf.size(), version));
  return buf;
}

void refresh_v2_crc(std::vector<std::uint8_t>& b) {
  const std::size_t body = b.size() - 4;
  const std::uint32_t c = crc32_ieee(b.data(), body);
  for (int i = 0; i < 4; ++i)
    b[body + static_cast<std::size_t>(i)] = static_cast<std::uint8_t>(c >> (8 * i));
}

std::uint32_t f32_bits(float v) {
  std::uint32_t u = 0;
  std::memcpy(&u, &v, 4);
  return u;
}

TEST(DatagramV2, SizesFollowTheRecordLength) {
  EXPECT_EQ(kJointRecordV2Bytes, 72u);
  EXPECT_EQ(datagram_size(0, kDatagramVersion2), 44u);
  EXPECT_EQ(datagram_size(14, kDatagramVersion2), 40u + 72u * 14u + 4u);  // the humanoid
  EXPECT_EQ(datagram_size(14), 40u + 32u * 14u + 4u);                     // v1 unchanged
  EXPECT_EQ(kMaxDatagramBytes, datagram_size(kMaxJoints, kDatagramVersion2));
}

TEST(DatagramV2, ByteLayoutOfOneJointMessage) {
  JointsMessage m;
  m.sequence = 0x0102030405060708ull;
  m.capture_ns = 1000;
  m.publish_ns = 2000;
  m.flags = 1;
  m.joint_count = 1;
  m.joints[0] = JointRecord{7, 1, 1, {0.5f, 0.0f, 0.0f}, {1.0f, 0.0f, 0.0f, 0.0f}};
  m.quality[0].solved_by = 2;
  m.quality[0].sd_rad[0] = 0.25f;
  m.rates[0].valid = 1;
  m.rates[0].rate_rad_s[0] = -1.5f;
  m.rates[0].sd_rad_s[0] = 0.125f;
  const auto b = encode(m, kDatagramVersion2);
  ASSERT_EQ(b.size(), 116u);
  EXPECT_EQ(0, std::memcmp(b.data(), "MCAP", 4));
  EXPECT_EQ(b[4], 2);  // version, little-endian
  EXPECT_EQ(b[5], 0);
  EXPECT_EQ(b[6], 1);     // J
  EXPECT_EQ(b[8], 0x08);  // sequence, little-endian
  const std::uint8_t* r = b.data() + 40;
  EXPECT_EQ(r[0], 7);  // the v1 record: index, type, valid, a, q
  EXPECT_EQ(r[2], 1);
  EXPECT_EQ(r[3], 1);
  auto f32_at = [&](std::size_t off) {
    std::uint32_t u = 0;
    for (int i = 3; i >= 0; --i) u = (u << 8) | r[off + static_cast<std::size_t>(i)];
    return u;
  };
  EXPECT_EQ(f32_at(4), f32_bits(0.5f));
  EXPECT_EQ(f32_at(16), f32_bits(1.0f));
  EXPECT_EQ(r[32], 2);  // solved_by: chain
  EXPECT_EQ(r[33], 1);  // rate_valid
  EXPECT_EQ(r[34], 0);
  EXPECT_EQ(r[35], 0);
  EXPECT_EQ(f32_at(36), f32_bits(0.25f));   // sd of a0
  EXPECT_EQ(f32_at(48), f32_bits(-1.5f));   // da0
  EXPECT_EQ(f32_at(60), f32_bits(0.125f));  // sd of da0
  const std::uint32_t crc = crc32_ieee(b.data(), 112);
  EXPECT_EQ(b[112], crc & 0xFFu);
  EXPECT_EQ(b[115], crc >> 24);
}

TEST(DatagramV2, RoundTripForEveryJointCountReportsTheVersion) {
  std::mt19937 rng(11);
  for (std::uint16_t j = 0; j <= kMaxJoints; ++j) {
    const JointsMessage m = random_v2_message(rng, j);
    for (const std::uint16_t version : {kDatagramVersion, kDatagramVersion2}) {
      const auto bytes = encode(m, version);
      ASSERT_EQ(bytes.size(), datagram_size(j, version));
      JointsMessage out;
      out.quality[0].solved_by = 9;  // must be overwritten either way
      std::uint16_t got = 0;
      ASSERT_EQ(decode_datagram(bytes.data(), bytes.size(), out, &got), DecodeStatus::kOk);
      EXPECT_EQ(got, version);
      ASSERT_EQ(out.joint_count, j);
      EXPECT_EQ(0, std::memcmp(out.joints, m.joints, sizeof(JointRecord) * j));
      for (std::size_t k = 0; k < j; ++k) {
        if (version == kDatagramVersion2) {
          EXPECT_EQ(0, std::memcmp(&out.quality[k], &m.quality[k], sizeof(JointQuality)));
          EXPECT_EQ(0, std::memcmp(&out.rates[k], &m.rates[k], sizeof(JointRates)));
        } else {  // v1 carries neither: defaults, never stale values
          EXPECT_EQ(out.quality[k].solved_by, 0);
          EXPECT_EQ(out.rates[k].valid, 0);
          EXPECT_EQ(out.rates[k].rate_rad_s[0], 0.0f);
        }
      }
    }
  }
}

TEST(DatagramV2, UnknownVersionIsNotEncoded) {
  JointsMessage m;
  m.joint_count = 1;
  std::vector<std::uint8_t> buf(kMaxDatagramBytes);
  EXPECT_EQ(encode_datagram(m, buf.data(), buf.size(), 3), 0u);
  EXPECT_EQ(encode_datagram(m, buf.data(), buf.size(), 0), 0u);
  EXPECT_EQ(encode_datagram(m, buf.data(), datagram_size(1, 2) - 1, 2), 0u);
}

TEST(DatagramV2, CorruptionsAreRejectedAndTheOutputUntouched) {
  std::mt19937 rng(12);
  const JointsMessage m = random_v2_message(rng, 3);
  const auto good = encode(m, kDatagramVersion2);
  JointsMessage sentinel;
  sentinel.sequence = 4242;
  sentinel.rates[0].valid = 1;
  sentinel.rates[0].rate_rad_s[0] = 9.0f;
  for (std::size_t i = 0; i < good.size(); ++i) {
    for (int bit = 0; bit < 8; ++bit) {
      auto bad = good;
      bad[i] ^= static_cast<std::uint8_t>(1u << bit);
      JointsMessage out = sentinel;
      ASSERT_NE(decode_datagram(bad.data(), bad.size(), out), DecodeStatus::kOk) << i << ":" << bit;
      ASSERT_EQ(out.sequence, 4242u);
      ASSERT_EQ(out.rates[0].rate_rad_s[0], 9.0f);
    }
  }
  for (std::size_t n = 0; n < good.size(); ++n) {
    JointsMessage out;
    EXPECT_NE(decode_datagram(good.data(), n, out), DecodeStatus::kOk) << n;
  }
  // Tail bytes out of range, with a valid CRC.
  JointsMessage out;
  auto bad = good;
  bad[40 + 32] = 3;  // solved_by 3 does not exist
  refresh_v2_crc(bad);
  EXPECT_EQ(decode_datagram(bad.data(), bad.size(), out), DecodeStatus::kBadRecord);
  bad = good;
  bad[40 + 72 + 33] = 2;  // rate_valid of the second record
  refresh_v2_crc(bad);
  EXPECT_EQ(decode_datagram(bad.data(), bad.size(), out), DecodeStatus::kBadRecord);
  bad = good;
  bad[4] = 1;  // a v2 body announced as v1: the length does not fit
  refresh_v2_crc(bad);
  EXPECT_EQ(decode_datagram(bad.data(), bad.size(), out), DecodeStatus::kBadLength);
}

}  // namespace
