// Design: what the blob-file tests (test_blob_file.cpp: writing and reading back;
// test_blob_file_damage.cpp: damaged and hostile files) share: random blobs with every
// field's bits in play, a bit-exact comparison, a small file's header, and files of random
// frames (numbers with gaps) written and then checked against what was written.
#pragma once

#include <gtest/gtest.h>

#include <bit>
#include <cstdint>
#include <random>
#include <string>
#include <vector>

#include "formats/blob_file.h"

namespace mocap::test {

inline detect::Blob random_blob(std::mt19937_64& rng) {
  std::uniform_real_distribution<double> px(0.0, 1031.0);
  std::uniform_real_distribution<float> f(-10.0f, 500.0f);
  std::uniform_int_distribution<int> box(0, 1031);
  std::uniform_int_distribution<std::uint32_t> u16(0, 65535);
  detect::Blob b;
  b.x_px = px(rng);
  b.y_px = std::bit_cast<double>(rng() & 0x7fefffffffffffffull);  // any finite double
  b.area_px = f(rng);
  b.sum_dn = std::bit_cast<float>(static_cast<std::uint32_t>(rng()) & 0x7f7fffffu);
  b.peak_dn = static_cast<std::uint16_t>(u16(rng));
  b.background_dn = static_cast<std::uint16_t>(u16(rng));
  b.x_min = box(rng);
  b.y_min = box(rng);
  b.x_max = box(rng);
  b.y_max = box(rng);
  b.major_axis_px = f(rng);
  b.minor_axis_px = f(rng);
  b.roundness = f(rng);
  b.eccentricity = f(rng);
  b.orientation_rad = f(rng);
  b.flags = static_cast<std::uint32_t>(rng());
  return b;
}

inline void expect_same_bits(const detect::Blob& a, const detect::Blob& b) {
  EXPECT_EQ(std::bit_cast<std::uint64_t>(a.x_px), std::bit_cast<std::uint64_t>(b.x_px));
  EXPECT_EQ(std::bit_cast<std::uint64_t>(a.y_px), std::bit_cast<std::uint64_t>(b.y_px));
  EXPECT_EQ(std::bit_cast<std::uint32_t>(a.area_px), std::bit_cast<std::uint32_t>(b.area_px));
  EXPECT_EQ(std::bit_cast<std::uint32_t>(a.sum_dn), std::bit_cast<std::uint32_t>(b.sum_dn));
  EXPECT_EQ(a.peak_dn, b.peak_dn);
  EXPECT_EQ(a.background_dn, b.background_dn);
  EXPECT_EQ(a.x_min, b.x_min);
  EXPECT_EQ(a.y_min, b.y_min);
  EXPECT_EQ(a.x_max, b.x_max);
  EXPECT_EQ(a.y_max, b.y_max);
  for (auto m :
       {&detect::Blob::major_axis_px, &detect::Blob::minor_axis_px, &detect::Blob::roundness,
        &detect::Blob::eccentricity, &detect::Blob::orientation_rad})
    EXPECT_EQ(std::bit_cast<std::uint32_t>(a.*m), std::bit_cast<std::uint32_t>(b.*m));
  EXPECT_EQ(a.flags, b.flags);
}

inline BlobFileInfo test_info(std::uint32_t max_blobs = 64) {
  BlobFileInfo info;
  info.camera = "cam0";
  info.width = 1032;
  info.height = 776;
  info.max_blobs = max_blobs;
  return info;
}

struct Written {
  std::vector<std::int64_t> frames;
  std::vector<detect::BlobList> lists;
};

// Writes `n` frames (numbers with gaps) of random blob lists to `path`.
inline Written write_random(const std::string& path, int n, std::mt19937_64& rng,
                            int max_count = 20) {
  auto w = BlobFileWriter::create(path, test_info(), 0);
  EXPECT_TRUE(w.ok()) << w.error().message;
  Written out;
  std::int64_t frame = 0;
  for (int i = 0; i < n; ++i) {
    detect::BlobList list(64);
    const int count = static_cast<int>(rng() % static_cast<std::uint64_t>(max_count + 1));
    for (int k = 0; k < count; ++k) list.push_back(random_blob(rng));
    list.set_levels({std::bit_cast<double>(rng() & 0x3fffffffffffffffull), 1.0 / 3.0, 17.25});
    frame += 1 + static_cast<std::int64_t>(rng() % 3);
    EXPECT_TRUE(w->append(frame, frame * 4'000'000 + 7, list).ok());
    out.frames.push_back(frame);
    out.lists.push_back(list);
  }
  EXPECT_TRUE(w->close().ok());
  return out;
}

inline void expect_reads(const BlobFileReader& r, const Written& w, std::size_t n) {
  ASSERT_EQ(r.chunks().size(), n);
  detect::BlobList got(64);
  std::vector<std::uint8_t> scratch;
  for (std::size_t i = 0; i < n; ++i) {
    const BlobFileReader::Chunk* c = r.find(w.frames[i]);
    ASSERT_NE(c, nullptr);
    EXPECT_EQ(c->timestamp_ns, w.frames[i] * 4'000'000 + 7);
    ASSERT_TRUE(r.load(*c, got, scratch).ok());
    ASSERT_EQ(got.size(), w.lists[i].size());
    EXPECT_EQ(std::bit_cast<std::uint64_t>(got.levels().background_dn),
              std::bit_cast<std::uint64_t>(w.lists[i].levels().background_dn));
    EXPECT_EQ(got.levels().noise_dn, 1.0 / 3.0);
    EXPECT_EQ(got.levels().threshold_dn, 17.25);
    for (std::size_t k = 0; k < got.size(); ++k) expect_same_bits(got[k], w.lists[i][k]);
  }
}

}  // namespace mocap::test
