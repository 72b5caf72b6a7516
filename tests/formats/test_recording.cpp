// Tests of the recording folder: frames.csv round trip and errors, Recording::open's
// checks, missing frames (kMissing, not an error) and malformed frame files.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <filesystem>

#include "formats/pgm.h"
#include "formats/recording.h"
#include "formats/rig_yaml.h"
#include "tests/formats/formats_test_util.h"
#include "tests/support/alloc_counter.h"
#include "tests/support/test_support.h"

namespace mocap {
namespace {

using ::testing::HasSubstr;
using ::testing::StartsWith;

class FramesCsvTest : public ::testing::Test {
 protected:
  test::TempDir dir{"frames_csv"};
  std::string path = dir.file("frames.csv");

  std::string error_of(const std::string& text) {
    test::write_file(path, text);
    auto r = load_frames_csv(path);
    EXPECT_FALSE(r.ok());
    if (r.ok()) return {};
    EXPECT_EQ(r.error().message.find('\n'), std::string::npos);
    EXPECT_THAT(r.error().message, StartsWith(path + ": "));
    return r.error().message;
  }
};

TEST_F(FramesCsvTest, RoundTrip) {
  const std::vector<FrameEntry> frames = {
      {0, 0}, {1, 10'000'123}, {3, 30'000'456}, {4, 9'000'000'000'000'000'000}};
  ASSERT_TRUE(save_frames_csv(path, frames).ok());
  EXPECT_THAT(test::read_file(path), StartsWith("frame,timestamp_ns\n0,0\n1,10000123\n"));
  auto r = load_frames_csv(path);
  ASSERT_TRUE(r.ok()) << r.error().message;
  ASSERT_EQ(r->size(), frames.size());
  for (std::size_t i = 0; i < frames.size(); ++i) {
    EXPECT_EQ((*r)[i].frame, frames[i].frame);
    EXPECT_EQ((*r)[i].timestamp_ns, frames[i].timestamp_ns);
  }
}

TEST_F(FramesCsvTest, AcceptsCrLfAndExtraColumns) {
  test::write_file(path, "frame,timestamp_ns,exposure_us\r\n0,100,800\r\n1,200,800\r\n");
  auto r = load_frames_csv(path);
  ASSERT_TRUE(r.ok()) << r.error().message;
  ASSERT_EQ(r->size(), 2u);
  EXPECT_EQ((*r)[1].timestamp_ns, 200);
}

TEST_F(FramesCsvTest, EmptyFile) {
  EXPECT_THAT(error_of(""), HasSubstr("empty file (expected the header 'frame,timestamp_ns')"));
}

TEST_F(FramesCsvTest, HeaderOnly) {
  EXPECT_THAT(error_of("frame,timestamp_ns\n"), HasSubstr("no frames"));
}

TEST_F(FramesCsvTest, WrongHeader) {
  EXPECT_THAT(error_of("frame,time\n0,1\n"),
              HasSubstr("line 1: header 'frame,time' does not start with 'frame,timestamp_ns'"));
  EXPECT_THAT(error_of("0,100\n1,200\n"), HasSubstr("line 1: header '0,100'"));
}

TEST_F(FramesCsvTest, NonNumericFieldNamesTheLine) {
  EXPECT_THAT(error_of("frame,timestamp_ns\n0,100\n1,abc\n"),
              HasSubstr("line 3: column 'timestamp_ns': expected an integer, got 'abc'"));
  EXPECT_THAT(error_of("frame,timestamp_ns\n0,100\n1.5,200\n"),
              HasSubstr("line 3: column 'frame': expected an integer, got '1.5'"));
}

TEST_F(FramesCsvTest, TooFewFields) {
  EXPECT_THAT(error_of("frame,timestamp_ns\n0\n"), HasSubstr("line 2: expected 2 fields, got 1"));
}

TEST_F(FramesCsvTest, MustStartAtZero) {
  EXPECT_THAT(error_of("frame,timestamp_ns\n1,100\n"),
              HasSubstr("line 2: the first frame is 1, frames start at 0"));
}

TEST_F(FramesCsvTest, MustBeStrictlyIncreasing) {
  EXPECT_THAT(error_of("frame,timestamp_ns\n0,100\n2,200\n2,300\n"),
              HasSubstr("line 4: frame 2 does not follow frame 2 (must be strictly increasing)"));
}

TEST_F(FramesCsvTest, NegativeTimestamp) {
  EXPECT_THAT(error_of("frame,timestamp_ns\n0,-5\n"),
              HasSubstr("line 2: negative timestamp_ns -5"));
}

TEST(FrameFilePath, SixDigits) {
  EXPECT_EQ(frame_file_path("/rec", "cam1", 42), "/rec/cam1/000042.pgm");
  EXPECT_EQ(frame_file_path("rec", "cam0", 1234567), "rec/cam0/1234567.pgm");
}

class RecordingTest : public ::testing::Test {
 protected:
  test::TempDir dir{"recording"};
  Rig rig;

  void SetUp() override {
    rig = test::make_test_rig();
    for (auto& c : rig.cameras) {
      c.width = 16;
      c.height = 12;
    }
    ASSERT_TRUE(save_rig(dir.file("rig.yaml"), rig).ok());
    ASSERT_TRUE(save_frames_csv(dir.file("frames.csv"), {{0, 0}, {1, 1000}, {2, 2000}}).ok());
    for (const auto& c : rig.cameras) std::filesystem::create_directories(dir.file(c.name));
    for (int f = 0; f < 3; ++f) {
      for (const auto& c : rig.cameras) {
        Image img(16, 12, PixelFormat::kMono8, 255);
        img.row8(0)[0] = static_cast<std::uint8_t>(f + 1);
        if (!(f == 1 && c.name == "cam1")) {  // frame 1 of cam1 was dropped
          ASSERT_TRUE(write_pgm(frame_file_path(dir.path(), c.name, f), img.view()).ok());
        }
      }
    }
  }
};

TEST_F(RecordingTest, OpensAndLoadsFramesWithAMissingOne) {
  auto rec = Recording::open(dir.path());
  ASSERT_TRUE(rec.ok()) << rec.error().message;
  EXPECT_EQ(rec->frames().size(), 3u);
  EXPECT_EQ(rec->rig().cameras.size(), 2u);
  EXPECT_EQ(rec->dir(), dir.path());
  Image img;
  auto r = rec->load_frame(0, 2, img);
  ASSERT_TRUE(r.ok()) << r.error().message;
  EXPECT_EQ(*r, FrameLoad::kOk);
  EXPECT_EQ(img.row8(0)[0], 3);
  auto m = rec->load_frame(1, 1, img);
  ASSERT_TRUE(m.ok()) << m.error().message;
  EXPECT_EQ(*m, FrameLoad::kMissing);
  EXPECT_EQ(img.row8(0)[0], 3) << "a missing frame leaves the image untouched";
}

TEST_F(RecordingTest, ReplayDoesNotAllocate) {
  auto rec = Recording::open(dir.path());
  ASSERT_TRUE(rec.ok()) << rec.error().message;
  Image img;
  ASSERT_TRUE(rec->load_frame(0, 0, img).ok());
  test::AllocationScope scope;
  int ok = 0;
  for (int f = 0; f < 3; ++f) {
    for (int c = 0; c < 2; ++c) ok += rec->load_frame(c, f, img).ok() ? 1 : 0;
  }
  EXPECT_EQ(scope.count(), 0u);
  EXPECT_EQ(ok, 6);
}

TEST_F(RecordingTest, MissingRig) {
  std::filesystem::remove(dir.file("rig.yaml"));
  auto rec = Recording::open(dir.path());
  ASSERT_FALSE(rec.ok());
  EXPECT_EQ(rec.error().message, dir.file("rig.yaml") + ": cannot open: No such file or directory");
}

TEST_F(RecordingTest, MissingFramesCsv) {
  std::filesystem::remove(dir.file("frames.csv"));
  auto rec = Recording::open(dir.path());
  ASSERT_FALSE(rec.ok());
  EXPECT_EQ(rec.error().message,
            dir.file("frames.csv") + ": cannot open: No such file or directory");
}

TEST_F(RecordingTest, MissingCameraFolder) {
  std::filesystem::remove_all(dir.file("cam1"));
  auto rec = Recording::open(dir.path());
  ASSERT_FALSE(rec.ok());
  EXPECT_EQ(rec.error().message,
            dir.file("cam1") + ": missing folder of camera 'cam1' named in rig.yaml");
}

TEST_F(RecordingTest, MissingDirectory) {
  auto rec = Recording::open(dir.file("nothing"));
  ASSERT_FALSE(rec.ok());
  EXPECT_THAT(rec.error().message, StartsWith(dir.file("nothing") + ": not a recording folder"));
}

TEST_F(RecordingTest, MalformedFrameNamesTheFile) {
  test::write_file(frame_file_path(dir.path(), "cam0", 1), "P5\n16 12\n255\nshort");
  auto rec = Recording::open(dir.path());
  ASSERT_TRUE(rec.ok()) << rec.error().message;
  Image img;
  auto r = rec->load_frame(0, 1, img);
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.error().message, frame_file_path(dir.path(), "cam0", 1) +
                                   ": truncated pixel data: expected 192 bytes, got 5");
}

TEST_F(RecordingTest, FrameOfWrongSize) {
  ASSERT_TRUE(write_pgm(frame_file_path(dir.path(), "cam1", 1),
                        Image(8, 8, PixelFormat::kMono8, 255).view())
                  .ok());
  auto rec = Recording::open(dir.path());
  ASSERT_TRUE(rec.ok());
  Image img;
  auto r = rec->load_frame(1, 1, img);
  ASSERT_FALSE(r.ok());
  EXPECT_THAT(r.error().message, HasSubstr("000001.pgm: size 8x8 differs from the rig's 16x12"));
}

TEST_F(RecordingTest, BadCameraIndex) {
  auto rec = Recording::open(dir.path());
  ASSERT_TRUE(rec.ok());
  Image img;
  auto r = rec->load_frame(2, 0, img);
  ASSERT_FALSE(r.ok());
  EXPECT_THAT(r.error().message, HasSubstr("camera index 2 out of range (2 cameras)"));
}

}  // namespace
}  // namespace mocap
