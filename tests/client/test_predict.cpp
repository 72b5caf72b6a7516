// Design: tests of the client's prediction (client/predict.h): a joint moving at a known
// rate is predicted to +10 ms exactly, its sd grows as stated, angles wrap at +-pi, joints
// without rates are not predicted, and times beyond the horizon are refused; predicting
// along a smooth motion from noiseless rates errs by the neglected acceleration only.
#include <gtest/gtest.h>

#include <cmath>

#include "client/predict.h"
#include "tests/support/alloc_counter.h"

namespace mocap::client {
namespace {

JointsMessage two_joints() {
  JointsMessage m;
  m.capture_ns = 1'000'000'000;
  m.joint_count = 2;
  m.joints[0].type = static_cast<std::uint8_t>(JointKind::kBall);
  m.joints[0].valid = 1;
  m.joints[0].a[0] = 0.5f;
  m.joints[0].a[1] = -0.25f;
  m.joints[0].a[2] = 3.1f;
  m.quality[0].sd_rad[0] = m.quality[0].sd_rad[1] = m.quality[0].sd_rad[2] = 0.001f;
  m.rates[0].valid = 1;
  m.rates[0].rate_rad_s[0] = 2.0f;
  m.rates[0].rate_rad_s[1] = -1.0f;
  m.rates[0].rate_rad_s[2] = 10.0f;  // crosses +pi within 10 ms
  m.rates[0].sd_rad_s[0] = m.rates[0].sd_rad_s[1] = m.rates[0].sd_rad_s[2] = 0.1f;
  m.joints[1].type = static_cast<std::uint8_t>(JointKind::kHinge);
  m.joints[1].valid = 1;
  m.joints[1].a[0] = 1.0f;  // rates unknown (filter warming up)
  return m;
}

TEST(Predict, ExtrapolatesWithTheRatesAndGrowsTheSd) {
  const JointsMessage m = two_joints();
  JointPrediction p;
  ASSERT_EQ(predict(m, m.capture_ns + 10'000'000, p), PredictStatus::kOk);
  EXPECT_NEAR(p.dt_s, 0.010, 1e-12);
  ASSERT_EQ(p.joint_count, 2);
  EXPECT_EQ(p.joints[0].valid, 1);
  EXPECT_NEAR(p.joints[0].a_rad[0], 0.52, 1e-6);
  EXPECT_NEAR(p.joints[0].a_rad[1], -0.26, 1e-6);
  EXPECT_NEAR(p.joints[0].a_rad[2], 3.2 - 2.0 * M_PI, 1e-6);  // wrapped into (-pi, pi]
  EXPECT_NEAR(p.joints[0].sd_rad[0], std::sqrt(1e-6 + 1e-6), 1e-8);
  EXPECT_EQ(p.joints[1].valid, 0);  // no rates: copied, not predicted
  EXPECT_FLOAT_EQ(p.joints[1].a_rad[0], 1.0f);
}

TEST(Predict, RefusesBeyondTheHorizonAndEmptyMessages) {
  const JointsMessage m = two_joints();
  JointPrediction p;
  EXPECT_EQ(predict(m, m.capture_ns + 60'000'000, p), PredictStatus::kBeyondHorizon);
  EXPECT_EQ(p.joints[0].valid, 0);
  EXPECT_EQ(predict(m, m.capture_ns - 60'000'000, p), PredictStatus::kBeyondHorizon);
  EXPECT_EQ(predict(m, m.capture_ns + 60'000'000, p, 0.1), PredictStatus::kOk);
  JointsMessage empty;
  EXPECT_EQ(predict(empty, 0, p), PredictStatus::kNoMessage);
}

TEST(Predict, SmoothMotionTenMillisecondsAheadWithinATenthOfADegree) {
  // a(t) = 0.8 sin(2 pi 0.5 t): the fastest humanoid joint of the simulator's smooth motion
  // is slower. With exact rates the error is the neglected 0.5 a'' dt^2 only.
  double worst = 0.0;
  for (int k = 0; k < 1000; ++k) {
    const double t = 0.01 * k, w = 2.0 * M_PI * 0.5;
    JointsMessage m;
    m.capture_ns = static_cast<std::int64_t>(k) * 10'000'000;
    m.joint_count = 1;
    m.joints[0].type = static_cast<std::uint8_t>(JointKind::kHinge);
    m.joints[0].valid = 1;
    m.joints[0].a[0] = static_cast<float>(0.8 * std::sin(w * t));
    m.rates[0].valid = 1;
    m.rates[0].rate_rad_s[0] = static_cast<float>(0.8 * w * std::cos(w * t));
    JointPrediction p;
    ASSERT_EQ(predict(m, m.capture_ns + 10'000'000, p), PredictStatus::kOk);
    const double truth = 0.8 * std::sin(w * (t + 0.010));
    worst = std::max(worst, std::abs(static_cast<double>(p.joints[0].a_rad[0]) - truth));
  }
  // 0.5 * 0.8 * pi^2 * (0.01 s)^2 = 3.9e-4 rad = 0.023 deg, a quarter of the 0.1 deg target.
  EXPECT_LT(worst * 180.0 / M_PI, 0.025);
  EXPECT_GT(worst * 180.0 / M_PI, 0.02);
}

TEST(Predict, AllocatesNothing) {
  const JointsMessage m = two_joints();
  JointPrediction p;
  mocap::test::AllocationScope scope;
  for (int i = 0; i < 100; ++i) predict(m, m.capture_ns + i * 100'000, p);
  EXPECT_EQ(scope.count(), 0u);
}

}  // namespace
}  // namespace mocap::client
