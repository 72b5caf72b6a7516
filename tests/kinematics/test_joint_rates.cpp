// Tests of the causal joint-rate filter (kinematics/joint_rates.h): accuracy and stated
// sd against true rates of smooth motions (right and wrong stated angle noise), ramps
// across +-pi, restarts after gaps, skipped frames, time going back, configuration
// errors, and no allocation per frame.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>

#include "kinematics/joint_rates.h"
#include "tests/support/alloc_counter.h"

namespace mocap::kinematics {
namespace {

constexpr double kDeg = std::numbers::pi / 180.0;
constexpr std::int64_t kFrameNs = 10'000'000;  // 100 fps

JointAngles one_joint(JointType type) {
  JointAngles a;
  a.joints.resize(1);
  a.joints[0].type = type;
  return a;
}

struct Score {
  double rms_error_deg_s = 0.0;
  double rms_sd_deg_s = 0.0;
  int rated = 0;
};

// A hinge following amplitude sin(2 pi f t), measured with white noise of true_sd while the
// tracker states stated_sd; the score skips the first second (the filter's start).
Score sinusoid(double amplitude_deg, double f_hz, double true_sd_deg, double stated_sd_deg,
               int frames = 2000, unsigned seed = 7) {
  auto filter = JointRateFilter::create({}, {JointType::kHinge});
  EXPECT_TRUE(filter.ok());
  JointAngles a = one_joint(JointType::kHinge);
  std::mt19937 rng(seed);
  std::normal_distribution<double> noise(0.0, true_sd_deg * kDeg);
  double se = 0.0, ss = 0.0;
  Score s;
  const double w = 2.0 * std::numbers::pi * f_hz;
  for (int k = 0; k < frames; ++k) {
    const double t = k * 0.01;
    a.joints[0].valid = true;
    a.joints[0].a0 = amplitude_deg * kDeg * std::sin(w * t) + noise(rng);
    a.joints[0].sd_rad = {stated_sd_deg * kDeg, 0.0, 0.0};
    EXPECT_TRUE(filter->update(k * kFrameNs, a));
    if (k < 100) continue;
    EXPECT_TRUE(a.joints[0].rate_valid);
    const double truth = amplitude_deg * w * std::cos(w * t);
    const double e = a.joints[0].rate_rad_s[0] / kDeg - truth;
    se += e * e;
    ss += std::pow(a.joints[0].rate_sd_rad_s[0] / kDeg, 2);
    ++s.rated;
  }
  s.rms_error_deg_s = std::sqrt(se / s.rated);
  s.rms_sd_deg_s = std::sqrt(ss / s.rated);
  return s;
}

TEST(JointRates, SmoothMotionsWithinFiveDegPerSecondAndStatedSdCoversTheError) {
  // Amplitudes and frequencies of the simulator's and the reviewers' smooth motions (up to
  // 72 deg at 0.75 Hz: 340 deg/s), with the tracker's angle noise (0.05..0.1 deg).
  struct Case {
    double amplitude_deg, f_hz, sd_deg;
  };
  for (const Case c : {Case{72, 0.75, 0.05}, Case{40, 0.5, 0.1}, Case{20, 0.25, 0.1},
                       Case{72, 0.75, 0.1}, Case{5, 0.3, 0.05}, Case{0, 0.5, 0.1}}) {
    SCOPED_TRACE(::testing::Message()
                 << c.amplitude_deg << " deg at " << c.f_hz << " Hz, sd " << c.sd_deg);
    const Score s = sinusoid(c.amplitude_deg, c.f_hz, c.sd_deg, c.sd_deg);
    EXPECT_LT(s.rms_error_deg_s, 6.0);
    EXPECT_GT(s.rms_sd_deg_s, 0.5 * s.rms_error_deg_s);
    EXPECT_LT(s.rms_sd_deg_s, 2.0 * s.rms_error_deg_s);
  }
}

TEST(JointRates, StatedSdTooSmallOrTooLargeStillCovered) {
  for (const double ratio : {0.5, 2.0, 5.0}) {
    SCOPED_TRACE(::testing::Message() << "true sd = stated sd x " << ratio);
    const Score s = sinusoid(40, 0.5, 0.1 * ratio, 0.1);
    EXPECT_GT(s.rms_sd_deg_s, 0.5 * s.rms_error_deg_s);
    EXPECT_LT(s.rms_sd_deg_s, 2.0 * s.rms_error_deg_s);
  }
  // Without any stated sd (poses-only angles): the floor and the noise ratio take over.
  const Score s = sinusoid(40, 0.5, 0.1, 0.0);
  EXPECT_GT(s.rms_sd_deg_s, 0.5 * s.rms_error_deg_s);
  EXPECT_LT(s.rms_sd_deg_s, 2.0 * s.rms_error_deg_s);
}

TEST(JointRates, BallRampsAcrossPlusMinusPiKeepTheirRate) {
  auto filter = JointRateFilter::create({}, {JointType::kBall});
  ASSERT_TRUE(filter.ok());
  JointAngles a = one_joint(JointType::kBall);
  const double rates[3] = {200.0 * kDeg, -50.0 * kDeg, -300.0 * kDeg};
  for (int k = 0; k < 300; ++k) {
    const double t = k * 0.01;
    JointAngle& j = a.joints[0];
    j.valid = true;
    j.a0 = std::remainder(3.0 + rates[0] * t, 2.0 * std::numbers::pi);  // wraps at +pi
    j.a1 = 0.3 + rates[1] * t * 0.1;
    j.a2 = std::remainder(-3.0 + rates[2] * t, 2.0 * std::numbers::pi);  // wraps at -pi
    j.sd_rad = {0.05 * kDeg, 0.05 * kDeg, 0.05 * kDeg};
    ASSERT_TRUE(filter->update(k * kFrameNs, a));
    if (k < 50) continue;
    ASSERT_TRUE(j.rate_valid);
    EXPECT_NEAR(j.rate_rad_s[0], rates[0], 1.0 * kDeg) << k;
    EXPECT_NEAR(j.rate_rad_s[1], rates[1] * 0.1, 1.0 * kDeg) << k;
    EXPECT_NEAR(j.rate_rad_s[2], rates[2], 1.0 * kDeg) << k;
  }
  EXPECT_EQ(filter->counters().restarts, 1u);
}

TEST(JointRates, GapsRestartAfterTheBoundAndSkippedFramesDoNot) {
  RateFilterConfig config;
  config.max_gap_s = 0.05;
  config.warmup_observations = 3;
  auto filter = JointRateFilter::create(config, {JointType::kHinge});
  ASSERT_TRUE(filter.ok());
  JointAngles a = one_joint(JointType::kHinge);
  const double rate = 30.0 * kDeg;
  auto feed = [&](int k, bool valid) {
    a.joints[0].valid = valid;
    a.joints[0].a0 = rate * k * 0.01;
    a.joints[0].sd_rad = {0.05 * kDeg, 0, 0};
    EXPECT_TRUE(filter->update(k * kFrameNs, a));
    return a.joints[0];
  };
  EXPECT_FALSE(feed(0, true).rate_valid);
  EXPECT_FALSE(feed(1, true).rate_valid);
  EXPECT_TRUE(feed(2, true).rate_valid);  // the third observation
  for (int k = 3; k < 100; ++k) feed(k, true);
  EXPECT_NEAR(feed(100, true).rate_rad_s[0], rate, 0.5 * kDeg);
  // Four frames lost (40 ms < 50 ms): no restart, the rate carries on.
  for (int k = 101; k < 105; ++k) EXPECT_FALSE(feed(k, false).rate_valid);
  const JointAngle after_skip = feed(105, true);
  EXPECT_TRUE(after_skip.rate_valid);
  EXPECT_NEAR(after_skip.rate_rad_s[0], rate, 0.5 * kDeg);
  EXPECT_EQ(filter->counters().restarts, 1u);
  // Ten frames lost (100 ms > 50 ms): restart, no rate until warmed up again.
  for (int k = 106; k < 116; ++k) feed(k, false);
  EXPECT_FALSE(feed(116, true).rate_valid);
  EXPECT_EQ(filter->counters().restarts, 2u);
  EXPECT_FALSE(feed(117, true).rate_valid);
  EXPECT_TRUE(feed(118, true).rate_valid);
}

TEST(JointRates, TimeGoingBackIsSkippedAndCounted) {
  auto filter = JointRateFilter::create({}, {JointType::kHinge});
  ASSERT_TRUE(filter.ok());
  JointAngles a = one_joint(JointType::kHinge);
  a.joints[0].valid = true;
  for (int k = 0; k < 10; ++k) {
    a.joints[0].a0 = 0.01 * k;
    ASSERT_TRUE(filter->update(k * kFrameNs, a));
  }
  const double rate = a.joints[0].rate_rad_s[0];
  ASSERT_TRUE(filter->update(5 * kFrameNs, a));  // older than the last
  EXPECT_FALSE(a.joints[0].rate_valid);
  ASSERT_TRUE(filter->update(9 * kFrameNs, a));  // the same instant again
  EXPECT_EQ(filter->counters().time_reversals, 2u);
  a.joints[0].a0 = 0.1;
  ASSERT_TRUE(filter->update(10 * kFrameNs, a));
  EXPECT_TRUE(a.joints[0].rate_valid);
  EXPECT_NEAR(a.joints[0].rate_rad_s[0], rate, 0.1);
  filter->reset();
  EXPECT_EQ(filter->counters().time_reversals, 0u);
  ASSERT_TRUE(filter->update(0, a));  // after reset() time may start again
  EXPECT_EQ(filter->counters().restarts, 1u);
}

TEST(JointRates, ConfigurationErrorsNameTheKey) {
  const std::vector<JointType> types{JointType::kBall};
  RateFilterConfig c;
  c.max_gap_s = 0.0;
  auto e = JointRateFilter::create(c, types);
  ASSERT_FALSE(e.ok());
  EXPECT_NE(e.error().message.find("velocity.max_gap_ms"), std::string::npos);
  c = {};
  c.warmup_observations = 0;
  e = JointRateFilter::create(c, types);
  ASSERT_FALSE(e.ok());
  EXPECT_NE(e.error().message.find("velocity.warmup_frames"), std::string::npos);
  c = {};
  c.jerk_psd_rad2_s5 = std::nan("");
  EXPECT_FALSE(JointRateFilter::create(c, types).ok());
  // A wrongly sized frame is refused.
  auto f = JointRateFilter::create({}, types);
  ASSERT_TRUE(f.ok());
  JointAngles two;
  two.joints.resize(2);
  EXPECT_FALSE(f->update(0, two));
}

TEST(JointRates, NoAllocationPerFrameOnFourteenJoints) {
  std::vector<JointType> types;
  for (int i = 0; i < 14; ++i) types.push_back(i % 3 == 2 ? JointType::kHinge : JointType::kBall);
  auto filter = JointRateFilter::create({}, types);
  ASSERT_TRUE(filter.ok());
  JointAngles a;
  a.joints.resize(types.size());
  for (std::size_t i = 0; i < types.size(); ++i) a.joints[i].type = types[i];
  test::AllocationScope scope;
  for (int k = 0; k < 500; ++k) {
    for (std::size_t i = 0; i < a.joints.size(); ++i) {
      a.joints[i].valid = (k + static_cast<int>(i)) % 37 != 0;
      a.joints[i].a0 = std::sin(0.01 * k + static_cast<double>(i));
      a.joints[i].a1 = 0.5 * std::cos(0.013 * k);
      a.joints[i].a2 = 0.1 * k;
    }
    ASSERT_TRUE(filter->update(k * kFrameNs, a));
  }
  EXPECT_EQ(scope.count(), 0u);
}

}  // namespace
}  // namespace mocap::kinematics
