// `mocap discover` end to end: the discovered targets and model drive `mocap track
// --model`, whose joint angles must match the simulator's truth (a hinge up to a
// constant offset and sign, since the discovered body frames differ from the true
// ones; a ball joint through the frame-independent angle of R_rel(f) R_rel(f0)^T).
// And bad input: one-line errors naming the recording and the problem.
#include <gtest/gtest.h>

#include <cmath>
#include <map>

#include "formats/csv_outputs.h"
#include "tests/support/test_support.h"

namespace mocap {
namespace {

using test::run_mocap;

int lines_of(const std::string& s) { return test::line_count(s); }

TEST(DiscoverCli, DiscoveredModelTracksTheTrueAngles) {
  test::TempDir dir("discover_cli");
  const std::string rec = dir.file("rec"), out = dir.file("found"), trk = dir.file("track");
  auto sim = run_mocap("simulate --out " + rec + " --frames 150 --seed 11", 120);
  ASSERT_EQ(sim.exit_code, 0) << sim.output;
  auto disc = run_mocap("discover " + rec + " --out " + out + " --urdf " + out + "/robot.urdf --stats", 120);
  ASSERT_EQ(disc.exit_code, 0) << disc.output;
  EXPECT_NE(disc.output.find("discovered 3 bodies and 2 joints"), std::string::npos) << disc.output;
  EXPECT_NE(test::read_file(out + "/robot.urdf").find("<robot"), std::string::npos);
  auto track = run_mocap("track " + rec + " --targets " + out + "/targets.yaml --model " + out +
                             "/model.yaml --out " + trk,
                         120);
  ASSERT_EQ(track.exit_code, 0) << track.output;
  auto found = read_angles_csv(trk + "/angles.csv");
  ASSERT_TRUE(found) << found.error().message;
  auto truth = read_angles_csv(rec + "/gt/angles.csv");
  ASSERT_TRUE(truth) << truth.error().message;
  std::map<std::pair<JointType, std::int64_t>, AngleRow> true_rows;
  for (const AngleRow& r : *truth) true_rows[{r.type, r.frame}] = r;
  // Hinge: a0_found = s * a0_true + offset; ball: angle(R(f) R(f0)^T) equal.
  std::vector<double> sum, diff;
  std::vector<std::pair<double, double>> ball;  // (found, true) relative angles, deg
  const AngleRow* ball_f0 = nullptr;
  const AngleRow* ball_t0 = nullptr;
  for (const AngleRow& r : *found) {
    auto it = true_rows.find({r.type, r.frame});
    if (it == true_rows.end()) continue;
    const AngleRow& t = it->second;
    if (r.type == JointType::kHinge) {
      sum.push_back(r.angles_deg.x() + t.angles_deg.x());
      diff.push_back(r.angles_deg.x() - t.angles_deg.x());
    } else {
      if (ball_f0 == nullptr) {
        ball_f0 = &r;
        ball_t0 = &t;
      }
      const double a_found = r.q_parent_child.angularDistance(ball_f0->q_parent_child) * 57.29577951308232;
      const double a_true = t.q_parent_child.angularDistance(ball_t0->q_parent_child) * 57.29577951308232;
      ball.emplace_back(a_found, a_true);
    }
  }
  ASSERT_GE(diff.size(), 100U);
  ASSERT_GE(ball.size(), 100U);
  auto spread = [](const std::vector<double>& v) {
    double m = 0.0;
    for (double x : v) m += x;
    m /= static_cast<double>(v.size());
    double worst = 0.0;
    for (double x : v) worst = std::max(worst, std::abs(std::remainder(x - m, 360.0)));
    return worst;
  };
  EXPECT_LT(std::min(spread(sum), spread(diff)), 0.5);
  double worst_ball = 0.0;
  for (const auto& [a, b] : ball) worst_ball = std::max(worst_ball, std::abs(a - b));
  EXPECT_LT(worst_ball, 0.5);
}

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
  // A static scene: one pose held.
  ASSERT_EQ(run_mocap("simulate --out " + dir.file("still") + " --frames 40 --motion poses --poses 1", 60).exit_code, 0);
  r = run_mocap("discover " + dir.file("still") + " --out " + dir.file("o"), 30);
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_EQ(lines_of(r.output), 1) << r.output;
  EXPECT_NE(r.output.find("still: nothing moves"), std::string::npos) << r.output;
  // One body only: the whole robot turned rigidly (joints fixed).
  ASSERT_EQ(run_mocap("simulate --out " + dir.file("rigid") + " --frames 60 --motion viewpoints", 60).exit_code, 0);
  r = run_mocap("discover " + dir.file("rigid") + " --out " + dir.file("o"), 30);
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_EQ(lines_of(r.output), 1) << r.output;
  EXPECT_NE(r.output.find("rigid: one rigid body only"), std::string::npos) << r.output;
}

}  // namespace
}  // namespace mocap
