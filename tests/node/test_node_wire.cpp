// Tests of the camera-node wire codec (pipeline/node/node_wire.h): bit-exact round trips
// of the detector's every field, and one rejection per kind of bad message.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <random>
#include <vector>

#include "pipeline/node/node_wire.h"

namespace mocap::node {
namespace {

WireHeader good_header(std::uint32_t count) {
  WireHeader h;
  set_name(h.node, "node-a");
  set_name(h.camera, "cam0");
  h.frame_number = 42;
  h.capture_ns = 123456789;
  h.background_dn = 10.25;
  h.noise_dn = 1.5;
  h.threshold_dn = 31.0;
  h.blob_count = count;
  return h;
}

detect::BlobList random_blobs(std::size_t n, std::uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  detect::BlobList list(n);
  for (std::size_t i = 0; i < n; ++i) {
    detect::Blob b;
    b.x_px = 1280.0 * u(rng);  // every bit of the double matters
    b.y_px = 1024.0 * u(rng);
    b.area_px = static_cast<float>(50.0 * u(rng));
    b.sum_dn = static_cast<float>(9000.0 * u(rng));
    b.peak_dn = static_cast<std::uint16_t>(rng() % 4096);
    b.background_dn = static_cast<std::uint16_t>(rng() % 64);
    b.x_min = static_cast<int>(b.x_px) - 3;
    b.y_min = static_cast<int>(b.y_px) - 3;
    b.x_max = static_cast<int>(b.x_px) + 3;
    b.y_max = static_cast<int>(b.y_px) + 3;
    b.major_axis_px = static_cast<float>(5.0 * u(rng));
    b.minor_axis_px = static_cast<float>(4.0 * u(rng));
    b.roundness = static_cast<float>(u(rng));
    b.eccentricity = static_cast<float>(u(rng));
    b.orientation_rad = static_cast<float>(3.0 * u(rng) - 1.5);
    b.flags = rng() & 0x1f;
    list.push_back(b);
  }
  return list;
}

TEST(NodeWire, RoundTripIsBitExact) {
  const detect::BlobList in = random_blobs(200, 7);
  std::vector<std::uint8_t> bytes(kMaxBlobBytes);
  const std::uint32_t n = encode_blobs(in, bytes.data(), bytes.size());
  ASSERT_EQ(n, 200u);
  detect::BlobList out(512);
  ASSERT_EQ(decode_frame(good_header(n), bytes.data(), n * kBlobRecordBytes, out), WireError::kOk);
  ASSERT_EQ(out.size(), in.size());
  for (std::size_t i = 0; i < in.size(); ++i) {
    const detect::Blob& a = in[i];
    const detect::Blob& b = out[i];
    EXPECT_EQ(std::memcmp(&a.x_px, &b.x_px, sizeof a.x_px), 0);
    EXPECT_EQ(std::memcmp(&a.y_px, &b.y_px, sizeof a.y_px), 0);
    EXPECT_EQ(a.area_px, b.area_px);
    EXPECT_EQ(a.sum_dn, b.sum_dn);
    EXPECT_EQ(a.peak_dn, b.peak_dn);
    EXPECT_EQ(a.background_dn, b.background_dn);
    EXPECT_EQ(a.x_min, b.x_min);
    EXPECT_EQ(a.y_max, b.y_max);
    EXPECT_EQ(a.major_axis_px, b.major_axis_px);
    EXPECT_EQ(a.minor_axis_px, b.minor_axis_px);
    EXPECT_EQ(a.roundness, b.roundness);
    EXPECT_EQ(a.eccentricity, b.eccentricity);
    EXPECT_EQ(a.orientation_rad, b.orientation_rad);
    EXPECT_EQ(a.flags, b.flags);
  }
  EXPECT_EQ(out.levels().background_dn, 10.25);
  EXPECT_EQ(out.levels().threshold_dn, 31.0);
}

TEST(NodeWire, EncodeStopsAtTheBufferAndTheBound) {
  const detect::BlobList in = random_blobs(10, 3);
  std::vector<std::uint8_t> bytes(3 * kBlobRecordBytes + 5);
  EXPECT_EQ(encode_blobs(in, bytes.data(), bytes.size()), 3u);
}

TEST(NodeWire, RejectsEveryBadMessageAndLeavesTheListEmpty) {
  const detect::BlobList in = random_blobs(4, 11);
  std::vector<std::uint8_t> bytes(4 * kBlobRecordBytes);
  ASSERT_EQ(encode_blobs(in, bytes.data(), bytes.size()), 4u);
  detect::BlobList out(8);
  auto decode = [&](const WireHeader& h, std::size_t size) {
    out.clear();
    out.push_back(detect::Blob{});  // must be cleared by any outcome
    return decode_frame(h, bytes.data(), size, out);
  };
  WireHeader h = good_header(4);
  h.version = 2;
  EXPECT_EQ(decode(h, bytes.size()), WireError::kBadVersion);
  EXPECT_EQ(out.size(), 0u);
  h = good_header(4);
  h.flags = 0x80;
  EXPECT_EQ(decode(h, bytes.size()), WireError::kBadFlags);
  h.flags = kWireEndOfStream;  // an end of stream carries no blobs
  EXPECT_EQ(decode(h, bytes.size()), WireError::kBadFlags);
  h = good_header(4);
  std::memset(h.node, 'a', sizeof h.node);  // no NUL within the bound
  EXPECT_EQ(decode(h, bytes.size()), WireError::kBadName);
  set_name(h.node, "a b");
  EXPECT_EQ(decode(h, bytes.size()), WireError::kBadName);
  set_name(h.node, "");
  EXPECT_EQ(decode(h, bytes.size()), WireError::kBadName);
  h = good_header(4);
  EXPECT_EQ(decode(h, bytes.size() - 1), WireError::kBadSize);
  EXPECT_EQ(decode(good_header(3), bytes.size()), WireError::kBadSize);
  EXPECT_EQ(decode(good_header(kMaxBlobsPerMessage + 1), bytes.size()), WireError::kOversized);
  detect::BlobList small(2);
  EXPECT_EQ(decode_frame(good_header(4), bytes.data(), bytes.size(), small), WireError::kOversized);
  h = good_header(4);
  h.noise_dn = std::numeric_limits<double>::quiet_NaN();
  EXPECT_EQ(decode(h, bytes.size()), WireError::kBadValue);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  std::memcpy(bytes.data() + kBlobRecordBytes, &nan, sizeof nan);  // blob 1's x_px
  EXPECT_EQ(decode(good_header(4), bytes.size()), WireError::kBadValue);
  EXPECT_EQ(out.size(), 0u);
  EXPECT_EQ(decode_frame(good_header(0), nullptr, 0, out), WireError::kOk);
}

}  // namespace
}  // namespace mocap::node
