// Damaged frame files in a recording: `mocap track` must process every other frame and
// name the damaged file in a warning (truncated, empty, wrong magic, wrong size, a
// folder or a FIFO in place of the file), treat absent files as dropped frames, and get
// through hostile image content (all white, dense speckle, one huge blob) without a
// crash or a hang.
#include <sys/stat.h>

#include <filesystem>
#include <random>

#include "tests/reliability/damaged_fixture.h"

namespace mocap {
namespace {

using test::DamagedRecording;

constexpr int kWidth = 1032;  // the built-in scenario's rig
constexpr int kHeight = 776;

bool contains(const std::vector<long>& v, long x) {
  return std::find(v.begin(), v.end(), x) != v.end();
}

struct PgmDamage {
  const char* name;
  void (*apply)(const std::string& path);
};

void truncate_to(const std::string& path, std::uintmax_t bytes) {
  std::filesystem::resize_file(path, bytes);
}

const PgmDamage kPgmDamages[] = {
    {"empty", [](const std::string& p) { truncate_to(p, 0); }},
    {"truncated_pixels",
     [](const std::string& p) { truncate_to(p, std::filesystem::file_size(p) / 2); }},
    {"one_byte_short",
     [](const std::string& p) { truncate_to(p, std::filesystem::file_size(p) - 1); }},
    {"header_only", [](const std::string& p) { test::write_file(p, "P5\n1032 776\n255\n"); }},
    {"truncated_header", [](const std::string& p) { test::write_file(p, "P5\n1032 7"); }},
    {"ascii_pgm_magic",
     [](const std::string& p) { test::write_file(p, "P2\n2 2\n255\n0 0 0 0\n"); }},
    {"png_magic",
     [](const std::string& p) {
       test::write_file(p, std::string("\x89PNG\r\n\x1a\n\0\0\0\rIHDR", 16));
     }},
    {"wrong_size",
     [](const std::string& p) { test::write_file(p, "P5\n4 2\n255\n" + std::string(8, '\x10')); }},
    {"maxval_zero",
     [](const std::string& p) {
       test::write_file(p, "P5\n1032 776\n0\n" + std::string(1032 * 776, '\0'));
     }},
    {"maxval_too_large",
     [](const std::string& p) { test::write_file(p, "P5\n1032 776\n70000\n"); }},
    {"absurd_width",
     [](const std::string& p) { test::write_file(p, "P5\n99999999999999 776\n255\n"); }},
    {"negative_height", [](const std::string& p) { test::write_file(p, "P5\n1032 -776\n255\n"); }},
    {"endless_comment",
     [](const std::string& p) {
       test::write_file(p, "P5\n#" + std::string(10000, 'c') + "\n1032 776\n255\n");
     }},
    {"sixteen_bit_truncated",
     [](const std::string& p) {
       test::write_file(p, "P5\n1032 776\n4095\n" + std::string(1032 * 776, '\x01'));
     }},
    {"directory",
     [](const std::string& p) {
       std::filesystem::remove(p);
       std::filesystem::create_directory(p);
     }},
    {"fifo",
     [](const std::string& p) {
       std::filesystem::remove(p);
       ASSERT_EQ(::mkfifo(p.c_str(), 0600), 0);
     }},
    {"link_to_dev_zero",
     [](const std::string& p) {
       std::filesystem::remove(p);
       std::filesystem::create_symlink("/dev/zero", p);
     }},
};

class DamagedPgm : public ::testing::TestWithParam<PgmDamage> {};

TEST_P(DamagedPgm, IsWarnedAndTheOtherFramesAreTracked) {
  DamagedRecording d(std::string("pgm_") + GetParam().name);
  const std::string bad = d.frame(0, 2);
  GetParam().apply(bad);
  const test::RunResult r = d.track();
  ASSERT_TRUE(test::is_warned_success(r, bad));
  EXPECT_EQ(test::line_count(r.output), 1) << r.output;  // one warning, for the one damaged file
  const std::vector<long> frames = test::csv_frames(d.out() + "/poses.csv");
  EXPECT_FALSE(contains(frames, 2)) << "a frame with one camera yields no 3D points";
  EXPECT_TRUE(contains(frames, 1));
  EXPECT_TRUE(contains(frames, test::kDamagedFrames - 1))
      << "tracking went on after the damaged frame";
  EXPECT_NE(test::read_file(d.out() + "/stats.json")
                .find("\"frames\": " + std::to_string(test::kDamagedFrames)),
            std::string::npos);
}

INSTANTIATE_TEST_SUITE_P(Reliability, DamagedPgm, ::testing::ValuesIn(kPgmDamages),
                         [](const ::testing::TestParamInfo<PgmDamage>& i) {
                           return std::string(i.param.name);
                         });

TEST(DamagedRecording, MissingFramesAreDroppedSilently) {
  DamagedRecording d("missing");
  std::filesystem::remove(d.frame(1, 1));
  std::filesystem::remove(d.frame(0, 3));
  const test::RunResult r = d.track();
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_EQ(r.output, "");
  const std::vector<long> frames = test::csv_frames(d.out() + "/poses.csv");
  EXPECT_FALSE(contains(frames, 1));
  EXPECT_FALSE(contains(frames, 3));
  EXPECT_TRUE(contains(frames, 2));
  EXPECT_TRUE(contains(frames, test::kDamagedFrames - 1));
}

TEST(DamagedRecording, FramesListedBeyondTheFilesAreDropped) {
  DamagedRecording d("beyond");
  std::string csv = test::read_file(d.rec() + "/frames.csv");
  for (int f = test::kDamagedFrames; f < test::kDamagedFrames + 50; ++f) {
    csv += std::to_string(f) + "," + std::to_string(1000000000LL + 10000000LL * f) + "\n";
  }
  test::write_file(d.rec() + "/frames.csv", csv);
  const test::RunResult r = d.track();
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(test::read_file(d.out() + "/stats.json")
                .find("\"frames\": " + std::to_string(test::kDamagedFrames + 50)),
            std::string::npos);
  EXPECT_GT(test::csv_rows(d.out() + "/poses.csv"), 0);
}

TEST(DamagedRecording, EmptyCameraFolderTracksNothingButSucceeds) {
  DamagedRecording d("empty_cam");
  std::filesystem::remove_all(d.rec() + "/cam1");
  std::filesystem::create_directory(d.rec() + "/cam1");
  const test::RunResult r = d.track();
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_EQ(test::csv_rows(d.out() + "/points.csv"), 0);
  EXPECT_EQ(test::csv_rows(d.out() + "/poses.csv"), 0);
}

TEST(DamagedRecording, MissingCameraFolderIsAOneLineError) {
  DamagedRecording d("no_cam");
  std::filesystem::remove_all(d.rec() + "/cam1");
  EXPECT_TRUE(test::is_one_line_error(d.track(), d.rec() + "/cam1"));
}

TEST(DamagedRecording, AllWhiteFramesYieldNothingAndTheRestIsTracked) {
  DamagedRecording d("white");
  for (int f = 0; f < 3; ++f)
    test::write_pgm8(d.frame(0, f), kWidth, kHeight, [](int, int) { return std::uint8_t{255}; });
  const test::RunResult r = d.track();
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const std::vector<long> frames = test::csv_frames(d.out() + "/poses.csv");
  EXPECT_FALSE(contains(frames, 0));
  EXPECT_TRUE(contains(frames, test::kDamagedFrames - 1));
}

TEST(DamagedRecording, DenseSpeckleOverflowsTheDetectorWithoutHanging) {
  DamagedRecording d("speckle");
  std::mt19937 rng(7);
  std::uniform_int_distribution<int> pick(0, 15);
  // 2x2 bright dots on a 4-pixel grid, about 40 % of the cells lit: ~20000 candidate blobs
  // per image, far beyond max_blobs, in BOTH cameras (the worst case for triangulation).
  for (int c = 0; c < 2; ++c) {
    for (int f = 0; f < 2; ++f) {
      std::vector<std::uint8_t> lit(static_cast<std::size_t>(kWidth / 4 * (kHeight / 4)));
      for (auto& l : lit) l = pick(rng) < 6 ? 1 : 0;
      test::write_pgm8(d.frame(c, f), kWidth, kHeight, [&](int x, int y) {
        const bool on =
            lit[static_cast<std::size_t>(y / 4 * (kWidth / 4) + x / 4)] && x % 4 < 2 && y % 4 < 2;
        return static_cast<std::uint8_t>(on ? 230 : 8);
      });
    }
  }
  const test::RunResult r = d.track();
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const std::vector<long> frames = test::csv_frames(d.out() + "/poses.csv");
  EXPECT_TRUE(contains(frames, test::kDamagedFrames - 1));
}

TEST(DamagedRecording, OneHugeBlobIsRejectedNotFatal) {
  DamagedRecording d("huge_blob");
  test::write_pgm8(d.frame(1, 0), kWidth, kHeight, [](int x, int y) {
    return static_cast<std::uint8_t>(x > 100 && x < 900 && y > 100 && y < 700 ? 250 : 5);
  });
  const test::RunResult r = d.track();
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_TRUE(contains(test::csv_frames(d.out() + "/poses.csv"), 1));
}

}  // namespace
}  // namespace mocap
