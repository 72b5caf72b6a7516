// Tests of the `mocap track` and `mocap calibrate` command lines: help, one-line errors
// naming the file, and a run that writes the outputs.
#include <gtest/gtest.h>

#include <filesystem>

#include "tests/track/track_fixture.h"

namespace mocap {
namespace {

int count_lines(const std::string& s) {
  return static_cast<int>(std::count(s.begin(), s.end(), '\n'));
}

TEST(TrackCli, HelpListsTheSpecOptions) {
  const test::RunResult r = test::run_mocap("track --help");
  EXPECT_EQ(r.exit_code, 0);
  for (const char* opt : {"--targets", "--model", "--out", "--stats"}) {
    EXPECT_NE(r.output.find(opt), std::string::npos) << opt;
  }
}

TEST(TrackCli, MissingRecordingIsAOneLineError) {
  test::TempDir tmp("cli_missing");
  test::write_file(tmp.file("targets.yaml"), "bodies: []\n");
  const test::RunResult r = test::run_mocap("track " + tmp.file("nope") + " --targets " +
                                            tmp.file("targets.yaml") + " --out " + tmp.file("out"));
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_EQ(count_lines(r.output), 1) << r.output;
  EXPECT_NE(r.output.find("nope"), std::string::npos) << r.output;
}

TEST(TrackCli, BrokenTargetsFileIsAOneLineError) {
  sim::SimOptions so;
  so.frames = 12;
  so.stray = 3;
  const std::string& rec = test::simulated_recording("alloc", so);
  test::TempDir tmp("cli_targets");
  test::write_file(tmp.file("targets.yaml"),
                   "bodies:\n  - name: a\n    markers: [[0, 0, 0], [1, 2]]\n");
  const test::RunResult r = test::run_mocap("track " + rec + " --targets " +
                                            tmp.file("targets.yaml") + " --out " + tmp.file("out"));
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_EQ(count_lines(r.output), 1) << r.output;
  EXPECT_NE(r.output.find("targets.yaml"), std::string::npos) << r.output;
}

TEST(TrackCli, TracksAndCalibratesASimulatedRecording) {
  sim::SimOptions so;
  so.frames = 60;
  so.motion = sim::MotionKind::kPoses;
  const std::string& rec = test::simulated_recording("poses", so);
  test::TempDir tmp("cli_run");
  const test::RunResult cal =
      test::run_mocap("calibrate " + rec + " --targets " + rec + "/targets.yaml --joints " + rec +
                      "/joints.yaml --out " + tmp.file("model.yaml"));
  ASSERT_EQ(cal.exit_code, 0) << cal.output;
  // The refinement fits the markers the poses were fitted on (partial ones left out):
  // every body's marker residual stays at the noise level of whole markers.
  int bodies_reported = 0;
  for (std::size_t at = cal.output.find("\nbody "); at != std::string::npos;
       at = cal.output.find("\nbody ", at + 1)) {
    const std::size_t rms = cal.output.find("residual rms ", at);
    if (rms == std::string::npos) break;
    ++bodies_reported;
    EXPECT_LT(std::stod(cal.output.substr(rms + 13)), 0.1) << cal.output;
  }
  EXPECT_EQ(bodies_reported, 3) << cal.output;
  const test::RunResult r = test::run_mocap(
      "track " + rec + " --targets " + rec + "/targets.yaml --model " + tmp.file("model.yaml") +
      " --out " + tmp.file("out") + " --stats " + tmp.file("out/stats.json"));
  ASSERT_EQ(r.exit_code, 0) << r.output;
  for (const char* f : {"points.csv", "poses.csv", "angles.csv", "stats.json"}) {
    EXPECT_TRUE(std::filesystem::exists(tmp.file(std::string("out/") + f))) << f;
  }
  const std::string angles = test::read_file(tmp.file("out/angles.csv"));
  // The spec's columns, then the 2026-12 (docs/chain.md) and 2027-01 (docs/kinematics.md,
  // "Joint rates") extension columns.
  EXPECT_EQ(angles.rfind("frame,timestamp_ns,joint,type,a0,a1,a2,qw,qx,qy,qz,solved_by,sd_a0,sd_a1,"
                         "sd_a2,da0,da1,da2,sd_da0,sd_da1,sd_da2\n",
                         0),
            0u);
  EXPECT_NE(angles.find(",elbow,hinge,"), std::string::npos);
  EXPECT_NE(angles.find(",shoulder,ball,"), std::string::npos);
  // --config: the identification thresholds of a run configuration. Coverage mode
  // (min_whole_markers 0) reports at least the poses of the default.
  test::write_file(tmp.file("coverage.yaml"), "identification:\n  min_whole_markers: 0\n");
  const test::RunResult cov = test::run_mocap(
      "track " + rec + " --targets " + rec + "/targets.yaml --model " + tmp.file("model.yaml") +
      " --out " + tmp.file("cov") + " --config " + tmp.file("coverage.yaml") + " --quiet");
  ASSERT_EQ(cov.exit_code, 0) << cov.output;
  EXPECT_GE(count_lines(test::read_file(tmp.file("cov/poses.csv"))),
            count_lines(test::read_file(tmp.file("out/poses.csv"))));
}

TEST(TrackCli, BrokenConfigIsAOneLineErrorNamingTheKey) {
  test::TempDir tmp("cli_config");
  test::write_file(tmp.file("bad.yaml"), "identification:\n  partial_sigma_mm: -2\n");
  const test::RunResult r =
      test::run_mocap("track " + tmp.file("rec") + " --targets " + tmp.file("t.yaml") + " --out " +
                      tmp.file("out") + " --config " + tmp.file("bad.yaml"));
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_EQ(count_lines(r.output), 1) << r.output;
  EXPECT_NE(r.output.find("bad.yaml"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("partial_sigma_mm"), std::string::npos) << r.output;
}

}  // namespace
}  // namespace mocap
