// Command tests: `mocap simulate` writes a 100-frame recording end to end, prints one
// summary line, writes 4-camera recordings (--cameras 4, also --motion wand), and
// rejects bad options (also 1 and 9 cameras, 33 of the humanoid) with a one-line error.
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <string>

#include "tests/support/test_support.h"

namespace mocap::sim {
namespace {

namespace fs = std::filesystem;

TEST(SimCommand, WritesARecordingWithEveryFile) {
  test::TempDir dir("sim_cmd");
  const std::string out = dir.file("rec");
  const auto r = test::run_mocap("simulate --out " + out + " --frames 12");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_EQ(test::line_count(r.output), 1) << r.output;
  EXPECT_NE(r.output.find("12 frames"), std::string::npos);
  for (const char* f : {"rig.yaml", "frames.csv", "targets.yaml", "joints.yaml", "gt/poses.csv",
                        "gt/angles.csv", "gt/markers.csv", "gt/model_true.yaml", "cam0/000000.pgm",
                        "cam0/000011.pgm", "cam1/000011.pgm"}) {
    EXPECT_TRUE(fs::exists(out + "/" + f)) << f;
  }
  EXPECT_FALSE(fs::exists(out + "/cam0/000012.pgm"));
}

TEST(SimCommand, SceneAndRigOptions) {
  test::TempDir dir("sim_cmd_rig");
  const std::string out = dir.file("rec");
  const auto r = test::run_mocap("simulate --out " + out + " --frames 2 --scene stalks --rig " +
                                 test::source_dir() + "/docs/rigs/wide.yaml");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_EQ(test::line_count(r.output), 1) << r.output;
  EXPECT_NE(r.output.find("scene stalks"), std::string::npos) << r.output;
  EXPECT_NE(test::read_file(out + "/rig.yaml").find("fx: 560"), std::string::npos);
  const auto bad = test::run_mocap("simulate --out " + out + " --rig " + dir.file("none.yaml"));
  EXPECT_NE(bad.exit_code, 0);
  EXPECT_EQ(test::line_count(bad.output), 1) << bad.output;
  EXPECT_NE(bad.output.find("none.yaml"), std::string::npos) << bad.output;
}

// Occurrences of `needle` in `text`.
int count_of(const std::string& text, const std::string& needle) {
  int n = 0;
  for (std::size_t p = text.find(needle); p != std::string::npos; p = text.find(needle, p + 1)) ++n;
  return n;
}

TEST(SimCommand, FourCamerasWriteFourFolders) {
  test::TempDir dir("sim_cmd_4");
  const std::string out = dir.file("rec");
  const auto r = test::run_mocap("simulate --out " + out + " --frames 2 --cameras 4");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_EQ(test::line_count(r.output), 1) << r.output;
  EXPECT_NE(r.output.find("2 frames x 4 cameras"), std::string::npos) << r.output;
  for (int c = 0; c < 4; ++c) {
    EXPECT_TRUE(fs::exists(out + "/cam" + std::to_string(c) + "/000001.pgm")) << c;
  }
  EXPECT_FALSE(fs::exists(out + "/cam4"));
  EXPECT_EQ(count_of(test::read_file(out + "/rig.yaml"), "name: cam"), 4);
  const std::string gt = test::read_file(out + "/gt/markers.csv");
  EXPECT_EQ(gt.rfind("frame,body,marker,x,y,z,u0,v0,vis0,u1,v1,vis1,u2,v2,vis2,u3,v3,vis3,"
                     "frac0,merged0,dropped0,frac1,merged1,dropped1,frac2,merged2,dropped2,"
                     "frac3,merged3,dropped3\n",
                     0),
            0u)
      << gt.substr(0, 200);
}

TEST(SimCommand, FourCameraWandRecording) {
  test::TempDir dir("sim_cmd_4w");
  const std::string out = dir.file("wand");
  const auto r = test::run_mocap("simulate --out " + out + " --frames 2 --cameras 4 --motion wand");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("2 frames x 4 cameras (wand)"), std::string::npos) << r.output;
  EXPECT_EQ(count_of(test::read_file(out + "/gt/rig_true.yaml"), "name: cam"), 4);
  EXPECT_EQ(count_of(test::read_file(out + "/rig.yaml"), "name: cam"), 4);
  EXPECT_TRUE(fs::exists(out + "/cam3/000001.pgm"));
  EXPECT_EQ(test::read_file(out + "/gt/markers.csv")
                .rfind("frame,marker,x,y,z,u0,v0,vis0,u1,v1,vis1,u2,v2,vis2,u3,v3,vis3\n", 0),
            0u);
}

TEST(SimCommand, BadOptionsGiveOneLineErrors) {
  test::TempDir dir("sim_bad");
  const std::string out = dir.file("rec");
  for (const char* args :
       {"--bits 12", "--motion wobble", "--frames 0", "--dropout 1.5", "--blur -1",
        "--motion poses --frames 5", "--bits 16 --maxval 70000", "--fps 0", "--noise -1",
        "--scene arms", "--cameras 1", "--cameras 9", "--cameras 0", "--cameras 9 --motion wand",
        "--scene humanoid --cameras 33"}) {
    const auto r = test::run_mocap("simulate --out " + out + " " + std::string(args));
    EXPECT_NE(r.exit_code, 0) << args;
    EXPECT_EQ(test::line_count(r.output), 1) << args << ": " << r.output;
    EXPECT_EQ(r.output.rfind("mocap: simulate: ", 0), 0u) << args << ": " << r.output;
  }
  test::write_file(dir.file("file"), "x");
  const auto r = test::run_mocap("simulate --frames 2 --out " + dir.file("file") + "/sub");
  EXPECT_NE(r.exit_code, 0);
  EXPECT_EQ(test::line_count(r.output), 1) << r.output;
  EXPECT_NE(r.output.find("cannot create"), std::string::npos) << r.output;
}

}  // namespace
}  // namespace mocap::sim
