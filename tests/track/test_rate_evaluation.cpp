// Tests of the joint-rate evaluation (track/rate_evaluation.h): known rate errors and sds
// against a true ramp (also across +-180 deg), rows without rates or without both true
// neighbours left out, every sample pooled.
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

}  // namespace
}  // namespace mocap
