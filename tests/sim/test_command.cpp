// Command tests: `mocap simulate` writes a 100-frame recording end to end, prints one
// summary line, and rejects bad options with a one-line error.
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <string>

#include "tests/support/test_support.h"

namespace mocap::sim {
namespace {

namespace fs = std::filesystem;

TEST(SimCommand, WritesAHundredFrameRecording) {
  test::TempDir dir("sim_cmd");
  const std::string out = dir.file("rec");
  const auto r = test::run_mocap("simulate --out " + out + " --frames 100");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_EQ(test::line_count(r.output), 1) << r.output;
  EXPECT_NE(r.output.find("100 frames"), std::string::npos);
  for (const char* f : {"rig.yaml", "frames.csv", "targets.yaml", "joints.yaml", "gt/poses.csv",
                        "gt/angles.csv", "gt/markers.csv", "gt/model_true.yaml", "cam0/000000.pgm",
                        "cam0/000099.pgm", "cam1/000099.pgm"}) {
    EXPECT_TRUE(fs::exists(out + "/" + f)) << f;
  }
  EXPECT_FALSE(fs::exists(out + "/cam0/000100.pgm"));
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

TEST(SimCommand, BadOptionsGiveOneLineErrors) {
  test::TempDir dir("sim_bad");
  const std::string out = dir.file("rec");
  for (const char* args : {"--bits 12", "--motion wobble", "--frames 0", "--dropout 1.5",
                           "--blur -1", "--motion poses --frames 5", "--bits 16 --maxval 70000",
                           "--fps 0", "--noise -1", "--scene arms"}) {
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
