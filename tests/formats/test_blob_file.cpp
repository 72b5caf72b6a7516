// Tests of the blob file (formats/blob_file.h) and blob recordings (formats/recording.h),
// writing and reading: random round trips stored bit-exact, reads without allocation, the
// writer's refusals and its full-disk cut-back, a file written independently from the
// documented layout read and re-written byte for byte, and Recording's recognition and
// per-frame reads of a blob recording. Damaged files: test_blob_file_damage.cpp.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <random>

#include "formats/blob_file.h"
#include "formats/recording.h"
#include "tests/formats/blob_file_test_util.h"
#include "tests/formats/formats_test_util.h"
#include "tests/support/alloc_counter.h"
#include "tests/support/test_support.h"

namespace mocap {
namespace {

using test::expect_reads;
using test::expect_same_bits;
using test::test_info;
using test::write_random;
using test::Written;
using ::testing::HasSubstr;
using ::testing::StartsWith;

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
