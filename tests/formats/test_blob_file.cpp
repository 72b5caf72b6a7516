// Tests of the blob file (formats/blob_file.h) and blob recordings (formats/recording.h):
// random round trips stored bit-exact, truncation at every byte offset (torn tail: the
// whole frames before it read, one warning), a damaged chunk in the middle skipped and
// reported, header errors, hostile sizes, the full-disk writer, and Recording's
// recognition and per-frame reads of a blob recording.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <bit>
#include <filesystem>
#include <random>

#include "formats/blob_file.h"
#include "formats/recording.h"
#include "tests/formats/formats_test_util.h"
#include "tests/support/alloc_counter.h"
#include "tests/support/test_support.h"

namespace mocap {
namespace {

using ::testing::HasSubstr;
using ::testing::StartsWith;

detect::Blob random_blob(std::mt19937_64& rng) {
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

void expect_same_bits(const detect::Blob& a, const detect::Blob& b) {
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

BlobFileInfo test_info(std::uint32_t max_blobs = 64) {
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
Written write_random(const std::string& path, int n, std::mt19937_64& rng, int max_count = 20) {
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

void expect_reads(const BlobFileReader& r, const Written& w, std::size_t n) {
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

TEST(BlobFile, RandomRoundTripsAreBitExact) {
  test::TempDir dir("blob_rt");
  std::mt19937_64 rng(29);
  for (int trial = 0; trial < 20; ++trial) {
    const std::string path = dir.file("t" + std::to_string(trial) + ".blobs");
    const Written w = write_random(path, 1 + trial * 3, rng);
    std::vector<std::string> warnings;
    auto r = BlobFileReader::open(path, warnings);
    ASSERT_TRUE(r.ok()) << r.error().message;
    EXPECT_TRUE(warnings.empty());
    EXPECT_EQ(r->info().camera, "cam0");
    EXPECT_EQ(r->info().width, 1032);
    EXPECT_EQ(r->info().max_blobs, 64u);
    expect_reads(*r, w, w.frames.size());
    EXPECT_EQ(r->find(w.frames.back() + 1), nullptr);  // a frame not in the file: dropped
  }
}

TEST(BlobFile, ReadingAFrameAllocatesNothingOnceTheScratchHasGrown) {
  test::TempDir dir("blob_alloc");
  std::mt19937_64 rng(3);
  const Written w = write_random(dir.file("a.blobs"), 10, rng);
  std::vector<std::string> warnings;
  auto r = BlobFileReader::open(dir.file("a.blobs"), warnings);
  ASSERT_TRUE(r.ok());
  detect::BlobList got(64);
  std::vector<std::uint8_t> scratch(kBlobChunkHeaderBytes + 64 * kBlobRecordBytes + 4);
  test::AllocationScope counter;
  for (const BlobFileReader::Chunk& c : r->chunks()) ASSERT_TRUE(r->load(c, got, scratch).ok());
  EXPECT_EQ(counter.count(), 0u);
}

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

TEST(BlobFile, WriterRefusesBadInputAndCutsAFailedWriteBack) {
  test::TempDir dir("blob_writer");
  BlobFileInfo info = test_info(4);
  info.width = 70000;
  EXPECT_FALSE(BlobFileWriter::create(dir.file("a.blobs"), info).ok());
  info = test_info(4);
  auto w = BlobFileWriter::create(dir.file("a.blobs"), info, 0, 200);
  ASSERT_TRUE(w.ok());
  EXPECT_FALSE(BlobFileWriter::create(dir.file("a.blobs"), info).ok());  // exists
  detect::BlobList list(8);
  list.push_back(detect::Blob{});
  ASSERT_TRUE(w->append(3, 30, list).ok());  // 40 + 112 bytes
  auto again = w->append(3, 31, list);
  ASSERT_FALSE(again.ok());
  EXPECT_THAT(again.error().message, HasSubstr("does not follow frame 3"));
  for (int i = 0; i < 4; ++i) list.push_back(detect::Blob{});
  EXPECT_THAT(w->append(4, 40, list).error().message, HasSubstr("at most 4"));
  list.clear();
  list.push_back(detect::Blob{});
  auto full = w->append(5, 50, list);  // past the 200-byte budget: ENOSPC
  ASSERT_FALSE(full.ok());
  EXPECT_THAT(full.error().message, StartsWith(dir.file("a.blobs") + ": cannot write frame 5"));
  EXPECT_EQ(std::filesystem::file_size(dir.file("a.blobs")), 152u);  // cut back
  ASSERT_TRUE(w->close().ok());
  std::vector<std::string> warnings;
  auto r = BlobFileReader::open(dir.file("a.blobs"), warnings);
  ASSERT_TRUE(r.ok());
  EXPECT_TRUE(warnings.empty());
  EXPECT_EQ(r->chunks().size(), 1u);
}

// The fuzz seed three_frames.blobs was written by a Python script from docs/formats.md's
// byte layout (struct + zlib.crc32), independently of this writer: the reader reads it
// and the writer writes the same bytes for the same blobs.
TEST(BlobFile, MatchesTheDocumentedLayoutWrittenIndependently) {
  const std::string seed = test::source_dir() + "/tests/fuzz/corpus/blob_file/three_frames.blobs";
  std::vector<std::string> warnings;
  auto r = BlobFileReader::open(seed, warnings);
  ASSERT_TRUE(r.ok()) << r.error().message;
  EXPECT_TRUE(warnings.empty());
  ASSERT_EQ(r->chunks().size(), 3u);
  EXPECT_EQ(r->chunks()[2].frame, 3);
  EXPECT_EQ(r->chunks()[2].timestamp_ns, 12'000'000);
  auto blob = [](double x, double y, float area, std::uint32_t flags) {
    detect::Blob b;
    b.x_px = x;
    b.y_px = y;
    b.area_px = area;
    b.sum_dn = 300.0f;
    b.peak_dn = 200;
    b.background_dn = 10;
    b.x_min = static_cast<int>(x) - 2;
    b.y_min = static_cast<int>(y) - 2;
    b.x_max = static_cast<int>(x) + 2;
    b.y_max = static_cast<int>(y) + 2;
    b.major_axis_px = 4.0f;
    b.minor_axis_px = 3.9f;
    b.roundness = 0.97f;
    b.eccentricity = 0.2f;
    b.orientation_rad = 0.1f;
    b.flags = flags;
    return b;
  };
  detect::BlobList lists[3] = {detect::BlobList(8), detect::BlobList(8), detect::BlobList(8)};
  lists[0].push_back(blob(10.5, 20.25, 12.0f, 0));
  lists[0].push_back(blob(30.125, 5.5, 12.0f, 1));
  lists[2].push_back(blob(40.0, 40.0, 12.0f, 0));
  detect::BlobList got(8);
  std::vector<std::uint8_t> scratch;
  for (int i = 0; i < 3; ++i) {
    ASSERT_TRUE(r->load(r->chunks()[static_cast<std::size_t>(i)], got, scratch).ok());
    ASSERT_EQ(got.size(), lists[i].size());
    for (std::size_t k = 0; k < got.size(); ++k) expect_same_bits(got[k], lists[i][k]);
    EXPECT_EQ(got.levels().noise_dn, 1.5);
  }
  test::TempDir dir("blob_layout");
  BlobFileInfo info = test_info(8);
  info.width = 64;
  info.height = 48;
  auto w = BlobFileWriter::create(dir.file("w.blobs"), info);
  ASSERT_TRUE(w.ok());
  const std::int64_t frames[3] = {0, 1, 3};
  for (int i = 0; i < 3; ++i) {
    lists[i].set_levels({10.0, 1.5, 20.0});
    ASSERT_TRUE(w->append(frames[i], frames[i] * 4'000'000, lists[i]).ok());
  }
  ASSERT_TRUE(w->close().ok());
  EXPECT_TRUE(test::read_file(dir.file("w.blobs")) == test::read_file(seed));
}

// A blob recording: rig.yaml, frames.csv and blobs/<camera>.blobs.
TEST(BlobRecording, IsRecognisedAndReadPerFrame) {
  test::TempDir dir("blob_rec");
  test::write_file(dir.file("rig.yaml"), test::kValidRigYaml);
  test::write_file(dir.file("frames.csv"), "frame,timestamp_ns\n0,0\n1,4000000\n2,8000000\n");
  std::filesystem::create_directories(dir.file("blobs"));
  EXPECT_THAT(Recording::open(dir.path()).error().message, HasSubstr("missing folder"));
  detect::BlobList list(8);
  detect::Blob b;
  b.x_px = 100.125;
  list.push_back(b);
  for (const char* cam : {"cam0", "cam1"}) {
    BlobFileInfo info = test_info(8);
    info.camera = cam;
    auto w = BlobFileWriter::create(Recording::blob_file_path(dir.path(), cam), info);
    ASSERT_TRUE(w.ok());
    for (std::int64_t f : {0, 2}) {
      if (std::string(cam) == "cam0" || f == 0) {
        ASSERT_TRUE(w->append(f, f * 4'000'000, list).ok());
      }
    }
    ASSERT_TRUE(w->close().ok());
  }
  auto rec = Recording::open(dir.path());
  ASSERT_TRUE(rec.ok()) << rec.error().message;
  EXPECT_TRUE(rec->has_blobs());
  EXPECT_EQ(rec->max_blobs(), 8u);
  detect::BlobList got(8);
  std::vector<std::uint8_t> scratch;
  EXPECT_EQ(*rec->load_blobs(0, 2, got, scratch), FrameLoad::kOk);
  ASSERT_EQ(got.size(), 1u);
  EXPECT_EQ(got[0].x_px, 100.125);
  EXPECT_EQ(*rec->load_blobs(1, 2, got, scratch), FrameLoad::kMissing);  // cam1 dropped it
  EXPECT_EQ(*rec->load_blobs(0, 1, got, scratch), FrameLoad::kMissing);
  EXPECT_FALSE(rec->load_blobs(2, 0, got, scratch).ok());

  // A camera's file missing, or of another camera / image size: one-line errors.
  std::filesystem::rename(dir.file("blobs/cam1.blobs"), dir.file("blobs/x.blobs"));
  EXPECT_THAT(Recording::open(dir.path()).error().message,
              HasSubstr("missing blob file of camera 'cam1'"));
  std::filesystem::copy_file(dir.file("blobs/cam0.blobs"), dir.file("blobs/cam1.blobs"));
  EXPECT_THAT(Recording::open(dir.path()).error().message,
              HasSubstr("header: camera 'cam0', expected 'cam1'"));
}

}  // namespace
}  // namespace mocap
