// Tests of the PGM reader/writer: 8/16-bit round trips, header comments, every header
// and data error, the size check against the rig, and zero allocations when reading
// into an Image that already has the right size.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "formats/pgm.h"
#include "tests/support/alloc_counter.h"
#include "tests/support/test_support.h"

namespace mocap {
namespace {

using ::testing::HasSubstr;
using ::testing::StartsWith;

class PgmTest : public ::testing::Test {
 protected:
  test::TempDir dir{"pgm"};
  std::string path = dir.file("img.pgm");

  std::string error_of(const std::string& bytes) {
    test::write_file(path, bytes);
    Image img;
    auto r = read_pgm(path, img);
    EXPECT_FALSE(r.ok());
    if (r.ok()) return {};
    EXPECT_EQ(r.error().message.find('\n'), std::string::npos);
    EXPECT_THAT(r.error().message, StartsWith(path + ": "));
    return r.error().message;
  }
};

Image gradient8(int w, int h) {
  Image img(w, h, PixelFormat::kMono8, 255);
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) img.row8(y)[x] = static_cast<std::uint8_t>((x * 7 + y * 13) & 0xFF);
  }
  return img;
}

Image gradient16(int w, int h, std::uint16_t maxval) {
  Image img(w, h, PixelFormat::kMono16, maxval);
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      img.row16(y)[x] = static_cast<std::uint16_t>((x * 257 + y * 1031) % (maxval + 1));
    }
  }
  return img;
}

bool same_pixels(const Image& a, const Image& b) {
  return a.width() == b.width() && a.height() == b.height() && a.format() == b.format() &&
         a.maxval() == b.maxval() && a.size_bytes() == b.size_bytes() &&
         std::equal(a.data(), a.data() + a.size_bytes(), b.data());
}

TEST_F(PgmTest, RoundTrip8Bit) {
  const Image img = gradient8(37, 21);
  ASSERT_TRUE(write_pgm(path, img.view()).ok());
  Image back;
  ASSERT_TRUE(read_pgm(path, back).ok());
  EXPECT_TRUE(same_pixels(img, back));
}

TEST_F(PgmTest, RoundTrip16BitBigEndianOnDisk) {
  const Image img = gradient16(33, 17, 4095);
  ASSERT_TRUE(write_pgm(path, img.view()).ok());
  const std::string bytes = test::read_file(path);
  const std::string header = "P5\n33 17\n4095\n";
  ASSERT_EQ(bytes.size(), header.size() + 33 * 17 * 2);
  // Pixel (1, 0) = 257 -> bytes 0x01 0x01; pixel (2, 0) = 514 -> 0x02 0x02; (0, 1) = 1031.
  const std::size_t row1 = header.size() + 33 * 2;
  EXPECT_EQ(static_cast<unsigned char>(bytes[row1]), 1031 >> 8);
  EXPECT_EQ(static_cast<unsigned char>(bytes[row1 + 1]), 1031 & 0xFF);
  Image back;
  ASSERT_TRUE(read_pgm(path, back).ok());
  EXPECT_TRUE(same_pixels(img, back));
  EXPECT_EQ(back.format(), PixelFormat::kMono16);
  EXPECT_EQ(back.maxval(), 4095);
}

TEST_F(PgmTest, HeaderCommentsAndSmallMaxval) {
  test::write_file(path, std::string("P5\n# made by a camera\n3 # width\n2\n# max\n15\n") +
                             std::string("\x00\x01\x02\x0d\x0e\x0f", 6));
  Image img;
  auto r = read_pgm(path, img);
  ASSERT_TRUE(r.ok()) << r.error().message;
  EXPECT_EQ(img.width(), 3);
  EXPECT_EQ(img.height(), 2);
  EXPECT_EQ(img.format(), PixelFormat::kMono8);
  EXPECT_EQ(img.maxval(), 15);
  EXPECT_EQ(img.row8(1)[2], 15);
}

TEST_F(PgmTest, PixelDataStartingWithWhitespaceBytes) {
  // Pixel bytes that look like whitespace or '#' must not be taken for the header.
  test::write_file(path, std::string("P5 2 2 255\n") + std::string("\n# \t", 4));
  Image img;
  ASSERT_TRUE(read_pgm(path, img).ok());
  EXPECT_EQ(img.row8(0)[0], '\n');
  EXPECT_EQ(img.row8(0)[1], '#');
  EXPECT_EQ(img.row8(1)[1], '\t');
}

TEST_F(PgmTest, NoAllocationWhenReadingIntoSameSizeImage) {
  const Image a = gradient16(640, 480, 1023);
  Image b = gradient16(640, 480, 1023);
  for (int i = 0; i < 640; ++i) b.row16(3)[i] = 7;
  const std::string path_b = dir.file("b.pgm");
  ASSERT_TRUE(write_pgm(path, a.view()).ok());
  ASSERT_TRUE(write_pgm(path_b, b.view()).ok());
  Image img;
  ASSERT_TRUE(read_pgm(path, img).ok());  // first read allocates
  const std::uint8_t* buffer = img.data();
  {
    test::AllocationScope scope;
    const bool ok1 = read_pgm_expect(path_b, 640, 480, img).ok();
    const bool ok2 = read_pgm(path, img).ok();
    EXPECT_EQ(scope.count(), 0u);
    EXPECT_TRUE(ok1);
    EXPECT_TRUE(ok2);
  }
  EXPECT_EQ(img.data(), buffer);
  EXPECT_TRUE(same_pixels(img, a));
  // The counter does see the allocation of a first read (the check above can fail).
  Image fresh;
  test::AllocationScope first;
  ASSERT_TRUE(read_pgm(path, fresh).ok());
  EXPECT_GT(first.count(), 0u);
}

TEST_F(PgmTest, EveryTruncationIsAnErrorNeverACrash) {
  const Image img = gradient16(5, 3, 1000);
  ASSERT_TRUE(write_pgm(path, img.view()).ok());
  const std::string full = "P5\n# c\n" + test::read_file(path).substr(3);
  for (std::size_t n = 0; n < full.size(); ++n) {
    test::write_file(path, full.substr(0, n));
    Image out;
    auto r = read_pgm(path, out);
    ASSERT_FALSE(r.ok()) << n;
    EXPECT_THAT(r.error().message, StartsWith(path + ": "));
  }
  test::write_file(path, full);
  Image out;
  ASSERT_TRUE(read_pgm(path, out).ok());
  EXPECT_TRUE(same_pixels(img, out));
}

TEST_F(PgmTest, EmptyFile) { EXPECT_THAT(error_of(""), HasSubstr("empty file")); }

TEST_F(PgmTest, WrongMagic) {
  EXPECT_THAT(error_of("P2\n2 2\n255\n1 2 3 4\n"), HasSubstr("unsupported PGM/PNM magic 'P2'"));
  EXPECT_THAT(error_of("P6\n2 2\n255\n" + std::string(12, 'x')), HasSubstr("magic 'P6'"));
  EXPECT_THAT(error_of("GIF89a..."), HasSubstr("not a PGM file"));
}

TEST_F(PgmTest, MaxvalOutOfRange) {
  EXPECT_THAT(error_of("P5\n2 2\n0\nxxxx"), HasSubstr("maxval 0 out of range 1..65535"));
  EXPECT_THAT(error_of("P5\n2 2\n65536\nxxxxxxxx"), HasSubstr("maxval 65536 out of range"));
}

TEST_F(PgmTest, TruncatedHeader) {
  EXPECT_THAT(error_of("P5\n640 480\n"), HasSubstr("truncated header (no maxval)"));
  EXPECT_THAT(error_of("P5\n640"), HasSubstr("truncated header (no height)"));
  EXPECT_THAT(error_of("P5\n640 abc 255\n"), HasSubstr("height is not a number"));
}

TEST_F(PgmTest, TruncatedPixelData) {
  EXPECT_THAT(error_of("P5\n4 3\n255\n" + std::string(10, 'x')),
              HasSubstr("truncated pixel data: expected 12 bytes, got 10"));
  EXPECT_THAT(error_of("P5\n4 3\n1000\n" + std::string(23, 'x')),
              HasSubstr("truncated pixel data: expected 24 bytes, got 23"));
}

TEST_F(PgmTest, SizeOutOfRange) {
  EXPECT_THAT(error_of("P5\n0 3\n255\n"),
              HasSubstr("image size 0x3 out of range (1..16384 per side)"));
  EXPECT_THAT(error_of("P5\n100000 3\n255\n"), HasSubstr("image size 100000x3 out of range"));
  EXPECT_THAT(error_of("P5\n99999999999999999 3\n255\n"), HasSubstr("width is too large"));
}

TEST_F(PgmTest, SizeDiffersFromRig) {
  ASSERT_TRUE(write_pgm(path, gradient8(8, 6).view()).ok());
  Image img;
  auto r = read_pgm_expect(path, 1032, 776, img);
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.error().message, path + ": size 8x6 differs from the rig's 1032x776");
}

TEST_F(PgmTest, MissingFile) {
  Image img;
  auto r = read_pgm(dir.file("none.pgm"), img);
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.error().message, dir.file("none.pgm") + ": cannot open: No such file or directory");
}

TEST_F(PgmTest, WriteRejectsBadMaxval) {
  Image img(4, 4, PixelFormat::kMono16, 255);
  auto r = write_pgm(path, img.view());
  ASSERT_FALSE(r.ok());
  EXPECT_THAT(r.error().message, HasSubstr("maxval 255 does not fit a 16-bit image"));
  EXPECT_FALSE(write_pgm(path, ImageView{}).ok());
}

}  // namespace
}  // namespace mocap
