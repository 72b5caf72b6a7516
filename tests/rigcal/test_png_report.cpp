// Design: the PNG encoder (signature, chunk CRCs, IHDR fields, IDAT inflating back to
// the filtered rows), the coverage image and the report YAML.
#include <gtest/gtest.h>
#include <zlib.h>

#include "formats/png_writer.h"
#include "rigcal/report.h"
#include "tests/support/test_support.h"

namespace mocap::rigcal {
namespace {

std::uint32_t be32(const std::uint8_t* p) {
  return (std::uint32_t{p[0]} << 24) | (std::uint32_t{p[1]} << 16) | (std::uint32_t{p[2]} << 8) |
         std::uint32_t{p[3]};
}

TEST(Png, ChunksAndPixelsRoundTrip) {
  RgbImage img(5, 3);
  for (int y = 0; y < 3; ++y)
    for (int x = 0; x < 5; ++x)
      img.set(x, y, static_cast<std::uint8_t>(10 * x), static_cast<std::uint8_t>(50 * y), 7);
  img.set(-1, 0, 1, 2, 3);  // ignored
  auto png = encode_png(img);
  ASSERT_TRUE(png);
  const std::vector<std::uint8_t>& b = *png;
  const std::uint8_t sig[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1A, '\n'};
  ASSERT_GT(b.size(), 8u);
  EXPECT_EQ(std::memcmp(b.data(), sig, 8), 0);
  std::size_t pos = 8;
  std::vector<std::string> types;
  std::vector<std::uint8_t> idat;
  while (pos + 12 <= b.size()) {
    const std::uint32_t len = be32(&b[pos]);
    const std::string type(reinterpret_cast<const char*>(&b[pos + 4]), 4);
    const uLong crc = crc32(0L, &b[pos + 4], len + 4);
    EXPECT_EQ(be32(&b[pos + 8 + len]), static_cast<std::uint32_t>(crc)) << type;
    if (type == "IHDR") {
      EXPECT_EQ(be32(&b[pos + 8]), 5u);
      EXPECT_EQ(be32(&b[pos + 12]), 3u);
      EXPECT_EQ(b[pos + 16], 8);  // bit depth
      EXPECT_EQ(b[pos + 17], 2);  // RGB
    }
    if (type == "IDAT") idat.assign(&b[pos + 8], &b[pos + 8 + len]);
    types.push_back(type);
    pos += 12 + len;
  }
  EXPECT_EQ(pos, b.size());
  EXPECT_EQ(types, (std::vector<std::string>{"IHDR", "IDAT", "IEND"}));
  std::vector<std::uint8_t> raw(3 * (1 + 15));
  uLongf raw_size = raw.size();
  ASSERT_EQ(uncompress(raw.data(), &raw_size, idat.data(), idat.size()), Z_OK);
  ASSERT_EQ(raw_size, raw.size());
  EXPECT_EQ(raw[0], 0);                         // filter byte
  EXPECT_EQ(raw[1 + 3 * 4], 40);                // pixel (4, 0) red
  EXPECT_EQ(raw[16 * 2 + 1 + 3 * 2 + 1], 100);  // pixel (2, 2) green
  EXPECT_FALSE(encode_png(RgbImage(0, 0)));
}

TEST(Report, YamlAndCoverageFiles) {
  RigCalResult r;
  r.frames_total = 10;
  r.cameras.resize(2);
  r.quality.resize(2);
  r.quality[0].name = "left";
  r.quality[1].name = "right";
  r.cameras[0].width = r.cameras[1].width = 64;
  r.cameras[0].height = r.cameras[1].height = 48;
  r.quality[0].wand_points_px = {Vec2(1, 1), Vec2(63, 47)};
  r.warnings = {"a \"quoted\" warning"};
  RigCalOptions opt;
  EXPECT_EQ(format_report_yaml(r, opt).find("wand_centres"), std::string::npos);
  r.wand_centres.end_ball_views = 120;
  r.wand_centres.cut_deg = 40.0;
  r.wand_centres.mean_shift_px[0] = 0.0031;
  const std::string y = format_report_yaml(r, opt);
  EXPECT_NE(y.find("wand_centres: {rod_cut_deg: 40, chosen_from_recording: false, "
                   "end_ball_views: 120, outer_rim_used: 0.000,\n"),
            std::string::npos)
      << y;
  EXPECT_NE(y.find("               mean_shift_px: [0.00310, 0.00000, "), std::string::npos);
  EXPECT_NE(y.find("               cuts_deg: [20, 25, 30, "), std::string::npos);
  EXPECT_EQ(y.find("wand_centres_partly_hidden"), std::string::npos);  // none
  r.wand_centres_partly_hidden.end_ball_views = 60;
  r.wand_centres_partly_hidden.cut_deg = 50.0;
  r.wand_centres_partly_hidden.from_recording = true;
  const std::string y2 = format_report_yaml(r, opt);
  EXPECT_NE(y2.find("wand_centres_partly_hidden: {rod_cut_deg: 50, chosen_from_recording: true, "
                    "end_ball_views: 60, outer_rim_used: 0.000,\n"
                    "                             cuts_deg: [20, 25, 30, "),
            std::string::npos)
      << y2;
  EXPECT_NE(y.find("frames_total: 10"), std::string::npos);
  EXPECT_NE(y.find("camera_count: 2\n"), std::string::npos);
  EXPECT_NE(y.find("    t_cam_cam0_mm: [0.0000, 0.0000, 0.0000]\n"), std::string::npos) << y;
  EXPECT_NE(y.find("- \"a \\\"quoted\\\" warning\""), std::string::npos);
  const RgbImage cov = coverage_image(r.quality[0], r.cameras[0], 16, 12);
  EXPECT_EQ(cov.width, 32);
  EXPECT_EQ(cov.rgb[(0 * 32 + 0) * 3], 255);  // the dot at (1,1) -> (0,0)
  test::TempDir dir("rigcal_report");
  ASSERT_TRUE(write_report(dir.file("rep"), r, opt));
  EXPECT_EQ(test::read_file(dir.file("rep/report.yaml")), y2);
  EXPECT_EQ(test::read_file(dir.file("rep/coverage_right.png")).substr(1, 3), "PNG");
}

}  // namespace
}  // namespace mocap::rigcal
