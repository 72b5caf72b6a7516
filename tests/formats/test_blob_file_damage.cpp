// Tests of damaged blob files (formats/blob_file.h): truncation at every byte offset
// (torn tail: the whole frames before it read, one warning), a damaged chunk in the middle
// skipped and reported, header errors as one line naming the file, and a hostile blob
// count bounded by the header. Writing and reading whole files: test_blob_file.cpp.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <random>

#include "formats/blob_file.h"
#include "tests/formats/blob_file_test_util.h"
#include "tests/support/test_support.h"

namespace mocap {
namespace {

using test::expect_reads;
using test::write_random;
using test::Written;
using ::testing::HasSubstr;
using ::testing::StartsWith;

TEST(BlobFile, TruncationAtEveryOffsetKeepsEveryWholeFrame) {
  test::TempDir dir("blob_trunc");
  std::mt19937_64 rng(7);
  const std::string full = dir.file("full.blobs");
  const Written w = write_random(full, 4, rng, 3);
  const std::string bytes = test::read_file(full);
  std::vector<std::size_t> ends;  // byte offset after each whole chunk
  {
    std::vector<std::string> warnings;
    auto r = BlobFileReader::open(full, warnings);
    ASSERT_TRUE(r.ok());
    for (const auto& c : r->chunks())
      ends.push_back(c.offset + kBlobChunkHeaderBytes + c.count * kBlobRecordBytes + 4);
  }
  const std::size_t header = 32 + 4 + 4;  // "cam0"
  const std::string cut = dir.file("cut.blobs");
  for (std::size_t len = 0; len <= bytes.size(); ++len) {
    test::write_file(cut, bytes.substr(0, len));
    std::vector<std::string> warnings;
    auto r = BlobFileReader::open(cut, warnings);
    if (len < header) {
      ASSERT_FALSE(r.ok()) << len;
      EXPECT_THAT(r.error().message, StartsWith(cut + ": "));
      continue;
    }
    ASSERT_TRUE(r.ok()) << len << ": " << r.error().message;
    std::size_t whole = 0;
    while (whole < ends.size() && ends[whole] <= len) ++whole;
    expect_reads(*r, w, whole);
    const bool at_boundary = len == header || (whole > 0 && ends[whole - 1] == len);
    if (at_boundary) {
      EXPECT_TRUE(warnings.empty()) << len;
    } else {
      ASSERT_EQ(warnings.size(), 1u) << len;
      const std::size_t tail = whole > 0 ? ends[whole - 1] : header;
      EXPECT_THAT(warnings[0],
                  StartsWith(cut + ": torn tail at byte offset " + std::to_string(tail) + " ("));
      EXPECT_EQ(r->torn_bytes(), len - tail);
    }
  }
}

TEST(BlobFile, DamagedChunkInTheMiddleIsSkippedAndReported) {
  test::TempDir dir("blob_damage");
  std::mt19937_64 rng(11);
  const std::string path = dir.file("d.blobs");
  Written w = write_random(path, 5, rng, 4);
  std::vector<std::string> warnings;
  std::uint64_t second = 0, third = 0;
  {
    auto r = BlobFileReader::open(path, warnings);
    ASSERT_TRUE(r.ok());
    second = r->chunks()[1].offset;
    third = r->chunks()[2].offset;
  }
  for (std::uint64_t at :
       {second, second + 5, second + 20, third - 1}) {  // sync, count, frame, CRC
    std::string bytes = test::read_file(path);
    bytes[at] = static_cast<char>(bytes[at] ^ 0x5a);
    const std::string bad = dir.file("bad.blobs");
    test::write_file(bad, bytes);
    warnings.clear();
    auto r = BlobFileReader::open(bad, warnings);
    ASSERT_TRUE(r.ok()) << r.error().message;
    ASSERT_EQ(warnings.size(), 1u) << at;
    EXPECT_THAT(warnings[0], StartsWith(bad + ": damaged bytes at byte offset " +
                                        std::to_string(second) + ".." + std::to_string(third)));
    EXPECT_EQ(r->damaged_regions(), 1u);
    ASSERT_EQ(r->chunks().size(), 4u);
    EXPECT_EQ(r->find(w.frames[1]), nullptr);  // read as a dropped frame
    EXPECT_NE(r->find(w.frames[0]), nullptr);
    EXPECT_NE(r->find(w.frames[4]), nullptr);
  }
}

TEST(BlobFile, HeaderErrorsAreOneLine) {
  test::TempDir dir("blob_header");
  std::mt19937_64 rng(5);
  const std::string path = dir.file("h.blobs");
  write_random(path, 2, rng);
  const std::string good = test::read_file(path);
  struct Case {
    std::size_t at;
    char value;
    const char* needle;
  };
  const Case cases[] = {{0, 'X', "no \"MOCAPBLB\" magic"},
                        {8, 2, "blob file version 2, this mocap reads version 1"},
                        {12, 10, "blob record of 10 bytes"},
                        {14, 9, "inconsistent sizes"},
                        {33, 'A', "CRC mismatch"}};
  for (const Case& c : cases) {
    std::string bytes = good;
    bytes[c.at] = c.value;
    test::write_file(path, bytes);
    std::vector<std::string> warnings;
    auto r = BlobFileReader::open(path, warnings);
    ASSERT_FALSE(r.ok()) << c.needle;
    EXPECT_THAT(r.error().message, StartsWith(path + ": "));
    EXPECT_THAT(r.error().message, HasSubstr(c.needle));
    EXPECT_EQ(r.error().message.find('\n'), std::string::npos);
  }
  std::vector<std::string> warnings;
  auto none = BlobFileReader::open(dir.file("none.blobs"), warnings);
  ASSERT_FALSE(none.ok());
  EXPECT_THAT(none.error().message, HasSubstr("cannot open"));
}

TEST(BlobFile, HostileBlobCountIsBoundedByTheHeader) {
  test::TempDir dir("blob_hostile");
  std::mt19937_64 rng(9);
  const std::string path = dir.file("x.blobs");
  write_random(path, 3, rng, 2);
  std::string bytes = test::read_file(path);
  const std::size_t first_chunk = 40;
  for (int i = 0; i < 4; ++i) bytes[first_chunk + 4 + static_cast<std::size_t>(i)] = '\xff';
  test::write_file(path, bytes);
  std::vector<std::string> warnings;
  auto r = BlobFileReader::open(path, warnings);
  ASSERT_TRUE(r.ok());
  EXPECT_EQ(r->chunks().size(), 2u);
  ASSERT_EQ(warnings.size(), 1u);
  EXPECT_THAT(warnings[0], HasSubstr("damaged bytes at byte offset 40.."));
}

}  // namespace
}  // namespace mocap
