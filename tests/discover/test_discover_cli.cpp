// `mocap discover` on bad input: one-line errors naming the recording and the problem
// (missing or garbage recording, too few frames).
#include <gtest/gtest.h>

#include "tests/support/test_support.h"

namespace mocap {
namespace {

using test::run_mocap;

int lines_of(const std::string& s) { return test::line_count(s); }

TEST(DiscoverCli, BadInputIsOneLineNamingTheRecording) {
  test::TempDir dir("discover_bad");
  // Missing recording.
  auto r = run_mocap("discover " + dir.file("nothing") + " --out " + dir.file("o"), 30);
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_EQ(lines_of(r.output), 1) << r.output;
  EXPECT_NE(r.output.find(dir.file("nothing")), std::string::npos) << r.output;
  // Garbage recording: frames.csv is not a CSV of frames.
  test::write_file(dir.file("garbage/rig.yaml"), "cameras: [1, 2\n");
  test::write_file(dir.file("garbage/frames.csv"), "\x01\x02garbage\n");
  r = run_mocap("discover " + dir.file("garbage") + " --out " + dir.file("o"), 30);
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_EQ(lines_of(r.output), 1) << r.output;
  EXPECT_NE(r.output.find(dir.file("garbage")), std::string::npos) << r.output;
  // Too few frames.
  ASSERT_EQ(run_mocap("simulate --out " + dir.file("short") + " --frames 12", 60).exit_code, 0);
  r = run_mocap("discover " + dir.file("short") + " --out " + dir.file("o"), 30);
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_EQ(lines_of(r.output), 1) << r.output;
  EXPECT_NE(r.output.find("short: 12 frames, at least 30"), std::string::npos) << r.output;
  // A static scene and a single rigid body are the same one-line path
  // (DiscoverErrors.TooFewFramesAndStaticScene and .OneRigidBodyOnly test their messages
  // on point sequences, without simulating recordings here).
}

}  // namespace
}  // namespace mocap
