// Tests of the joint-rate evaluation (track/rate_evaluation.h): known rate errors and sds
// against a true ramp (also across +-180 deg), rows without rates or without both true
// neighbours left out, every sample pooled; body velocities against a body moving and
// turning at known rates (also through +-180 deg of rotation).
#include <gtest/gtest.h>

#include <cmath>

#include "track/rate_evaluation.h"

namespace mocap {
namespace {

AngleRow row(std::int64_t frame, const std::string& joint, JointType type, Vec3 angles_deg) {
  AngleRow r;
  r.frame = frame;
  r.timestamp_ns = frame * 10'000'000;
  r.joint = joint;
  r.type = type;
  r.angles_deg = angles_deg;
  return r;
}

TEST(RateErrors, KnownErrorsAndStatedSd) {
  std::vector<AngleRow> truth, measured;
  for (int f = 0; f < 50; ++f) {
    // hinge at 100 deg/s; ball a0 at -300 deg/s wrapping past -180, a1, a2 still.
    truth.push_back(row(f, "elbow", JointType::kHinge, Vec3(1.0 * f, 0, 0)));
    truth.push_back(row(f, "shoulder", JointType::kBall,
                        Vec3(std::remainder(170.0 - 3.0 * f, 360.0), 10.0, -5.0)));
    AngleRow h = row(f, "elbow", JointType::kHinge, Vec3(1.0 * f, 0, 0));
    h.has_rates = f >= 2;  // warming up
    h.rate_deg_s = Vec3(100.0 + (f % 2 ? 2.0 : -2.0), 0, 0);
    h.rate_sd_deg_s = Vec3(4.0, 0, 0);
    measured.push_back(h);
    if (f % 5 == 0) continue;  // the ball joint is missing in some frames
    AngleRow b = row(f, "shoulder", JointType::kBall, Vec3::Zero());
    b.has_rates = true;
    b.rate_deg_s = Vec3(-300.0 + 3.0, 3.0, -3.0);
    b.rate_sd_deg_s = Vec3(1.5, 1.5, 1.5);
    measured.push_back(b);
  }
  JointRateError all;
  const auto e = rate_errors(truth, measured, &all);
  ASSERT_EQ(e.size(), 2u);
  EXPECT_EQ(e[0].joint, "elbow");
  EXPECT_EQ(e[0].samples, 48 - 1);  // frames 2..48 (frame 49 has no true neighbour after)
  EXPECT_NEAR(e[0].rms_deg_s, 2.0, 1e-9);
  EXPECT_NEAR(e[0].rms_sd_deg_s, 4.0, 1e-9);
  EXPECT_NEAR(e[0].sd_ratio, 2.0, 1e-9);
  EXPECT_EQ(e[1].joint, "shoulder");
  EXPECT_EQ(e[1].samples, 3 * (48 - 9));   // frames 1..48 without the multiples of 5
  EXPECT_NEAR(e[1].rms_deg_s, 3.0, 1e-6);  // across the wrap too
  EXPECT_NEAR(e[1].max_deg_s, 3.0, 1e-6);
  EXPECT_NEAR(e[1].sd_ratio, 0.5, 1e-6);
  EXPECT_EQ(all.samples, e[0].samples + e[1].samples);
  EXPECT_EQ(all.joint, "all");
  const double pooled = std::sqrt((4.0 * 47 + 9.0 * 117) / (47 + 117));
  EXPECT_NEAR(all.rms_deg_s, pooled, 1e-6);
}

TEST(RateErrors, NoRatesNoSamples) {
  std::vector<AngleRow> truth{row(0, "neck", JointType::kBall, Vec3::Zero()),
                              row(1, "neck", JointType::kBall, Vec3::Zero()),
                              row(2, "neck", JointType::kBall, Vec3::Zero())};
  const std::vector<AngleRow> measured = truth;  // has_rates false: files without the columns
  JointRateError all;
  const auto e = rate_errors(truth, measured, &all);
  ASSERT_EQ(e.size(), 1u);
  EXPECT_EQ(e[0].samples, 0);
  EXPECT_EQ(all.samples, 0);
}

PoseRow pose(std::int64_t frame, const std::string& body, double t_s) {
  PoseRow p;
  p.frame = frame;
  p.timestamp_ns = frame * 10'000'000;
  p.body = body;
  // 500 mm/s along x, 90 deg/s about z (through 180 deg at 2 s).
  p.t_world_body = Vec3(500.0 * t_s, 0.0, 100.0);
  p.q_world_body = Quat(Eigen::AngleAxisd(t_s * 3.14159265358979 / 2.0, Vec3::UnitZ()));
  return p;
}

TEST(BodyRateErrors, KnownErrorsAndStatedSdThroughAHalfTurn) {
  std::vector<PoseRow> truth, measured;
  for (int f = 0; f < 300; ++f) {
    truth.push_back(pose(f, "hand", 0.01 * f));
    PoseRow m = pose(f, "hand", 0.01 * f);
    m.has_velocity = f % 3 != 0;
    m.v_world_mm_s = Vec3(500.0 + 10.0, 0.0, 0.0);  // 10 mm/s error on x only
    m.v_sd_mm_s = Vec3(10.0, 10.0, 10.0);
    m.w_world_deg_s = Vec3(0.0, 0.0, 90.0 - 3.0);  // 3 deg/s error on z only
    m.w_sd_deg_s = Vec3(1.0, 1.0, 1.0);
    measured.push_back(m);
  }
  BodyRateError all;
  const auto e = body_rate_errors(truth, measured, &all);
  ASSERT_EQ(e.size(), 1u);
  EXPECT_EQ(e[0].body, "hand");
  EXPECT_EQ(e[0].linear_mm_s.samples, 3 * 199);  // frames 1..298 but the multiples of 3
  EXPECT_NEAR(e[0].linear_mm_s.rms, 10.0 / std::sqrt(3.0), 1e-6);
  EXPECT_NEAR(e[0].linear_mm_s.max, 10.0, 1e-6);
  EXPECT_NEAR(e[0].angular_deg_s.rms, 3.0 / std::sqrt(3.0), 1e-6);
  EXPECT_NEAR(e[0].angular_deg_s.max, 3.0, 1e-6);
  EXPECT_NEAR(e[0].angular_deg_s.sd_ratio, 1.0 / std::sqrt(3.0), 1e-6);  // sd 1, RMS sqrt(3)
  EXPECT_EQ(all.body, "all");
  EXPECT_EQ(all.linear_mm_s.samples, e[0].linear_mm_s.samples);
  // Files without the columns: no samples.
  EXPECT_EQ(body_rate_errors(truth, truth)[0].linear_mm_s.samples, 0);
}

}  // namespace
}  // namespace mocap
