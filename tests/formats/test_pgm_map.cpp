// Tests of the zero-copy PGM mapping (formats/pgm_map.h, Recording::map_frame): the view
// equals what the reader reads, header comments included; a missing file, a 16-bit
// file (left to the reader), a size other than the rig's and a directory; unmapping on
// reset, move and destruction. (Every malformed header: test_pgm.cpp's error_of checks
// the mapping gives the reader's line.)
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <utility>

#include "formats/pgm.h"
#include "formats/pgm_map.h"
#include "tests/support/test_support.h"

namespace mocap {
namespace {

using ::testing::HasSubstr;

Image pgm_map_test_image(int w, int h) {
  Image img(w, h, PixelFormat::kMono8, 200);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) img.row8(y)[x] = static_cast<std::uint8_t>((x * 3 + y * 11) % 201);
  return img;
}

bool same_view(const ImageView& a, const Image& b) {
  if (a.width != b.width() || a.height != b.height() || a.format != b.format() ||
      a.maxval != b.maxval())
    return false;
  for (int y = 0; y < a.height; ++y)
    for (int x = 0; x < a.width; ++x)
      if (a.row8(y)[x] != b.view().row8(y)[x]) return false;
  return true;
}

TEST(PgmMap, ViewEqualsTheReadImage) {
  test::TempDir dir{"pgm_map"};
  const std::string path = dir.file("a.pgm");
  const Image img = pgm_map_test_image(1283, 7);  // odd width: no row padding assumed
  ASSERT_TRUE(write_pgm(path, img.view()).ok());
  MappedPgm m;
  auto r = map_pgm_path(path.c_str(), 1283, 7, m);
  ASSERT_TRUE(r.ok()) << r.error().message;
  EXPECT_EQ(*r, PgmMapResult::kMapped);
  ASSERT_TRUE(m.mapped());
  EXPECT_EQ(m.view().stride_bytes, 1283);
  EXPECT_TRUE(same_view(m.view(), img));
}

TEST(PgmMap, CommentsInTheHeader) {
  test::TempDir dir{"pgm_map"};
  const std::string path = dir.file("c.pgm");
  test::write_file(path, std::string("P5 # made by hand\n3 # w\n2\n# maxval next\n9\n") +
                             std::string("\x01\x02\x03\x04\x05\x06", 6));
  MappedPgm m;
  auto r = map_pgm_path(path.c_str(), 0, 0, m);
  ASSERT_TRUE(r.ok()) << r.error().message;
  ASSERT_EQ(*r, PgmMapResult::kMapped);
  EXPECT_EQ(m.view().maxval, 9);
  EXPECT_EQ(m.view().row8(1)[2], 6);
}

TEST(PgmMap, MissingSixteenBitWrongSizeAndDirectory) {
  test::TempDir dir{"pgm_map"};
  MappedPgm m;
  auto missing = map_pgm_path(dir.file("none.pgm").c_str(), 0, 0, m);
  ASSERT_TRUE(missing.ok());
  EXPECT_EQ(*missing, PgmMapResult::kMissing);

  const std::string wide = dir.file("w.pgm");
  Image img16(4, 3, PixelFormat::kMono16, 4095);
  ASSERT_TRUE(write_pgm(wide, img16.view()).ok());
  auto needs_copy = map_pgm_path(wide.c_str(), 4, 3, m);
  ASSERT_TRUE(needs_copy.ok());
  EXPECT_EQ(*needs_copy, PgmMapResult::kNeedsCopy);
  EXPECT_FALSE(m.mapped());

  const std::string small = dir.file("s.pgm");
  ASSERT_TRUE(write_pgm(small, pgm_map_test_image(4, 3).view()).ok());
  auto size = map_pgm_path(small.c_str(), 5, 3, m);
  ASSERT_FALSE(size.ok());
  EXPECT_THAT(size.error().message, HasSubstr(small + ": size 4x3 differs from the rig's 5x3"));

  auto directory = map_pgm_path(dir.path().c_str(), 0, 0, m);
  ASSERT_FALSE(directory.ok());
  EXPECT_THAT(directory.error().message, HasSubstr("not a regular file"));
  EXPECT_FALSE(m.mapped());
}

TEST(PgmMap, ResetMoveAndRemap) {
  test::TempDir dir{"pgm_map"};
  const std::string a = dir.file("a.pgm"), b = dir.file("b.pgm");
  ASSERT_TRUE(write_pgm(a, pgm_map_test_image(8, 8).view()).ok());
  ASSERT_TRUE(write_pgm(b, pgm_map_test_image(16, 4).view()).ok());
  MappedPgm m;
  ASSERT_TRUE(map_pgm_path(a.c_str(), 0, 0, m).ok());
  MappedPgm moved = std::move(m);
  EXPECT_FALSE(m.mapped());  // NOLINT(bugprone-use-after-move): moved-from is empty
  EXPECT_TRUE(moved.mapped());
  EXPECT_EQ(moved.view().width, 8);
  ASSERT_TRUE(map_pgm_path(b.c_str(), 0, 0, moved).ok());  // replaces the mapping
  EXPECT_EQ(moved.view().width, 16);
  moved.reset();
  EXPECT_FALSE(moved.mapped());
  EXPECT_TRUE(moved.view().empty());
}

}  // namespace
}  // namespace mocap
