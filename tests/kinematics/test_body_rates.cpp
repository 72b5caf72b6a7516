// Tests of the causal body-velocity filter (kinematics/body_rates.h): linear and angular
// velocity against the analytic rates of a smooth 6-DOF motion with noisy poses (the stated
// sd covers the error), a spin faster than half a turn per 100 ms frame-to-frame through
// many turns, restarts after gaps, a lost body keeping no stale velocity, time going back,
// configuration errors, and no allocation per frame.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <numbers>
#include <random>
#include <vector>

#include "kinematics/body_rates.h"
#include "tests/support/alloc_counter.h"

namespace mocap::kinematics {
namespace {

constexpr double kPiB = std::numbers::pi;
constexpr std::int64_t kStepNs = 10'000'000;  // 100 fps

// A hand-like motion: the origin on a Lissajous path (~1.5 m/s), the orientation
// R(t) = Rz(a sin(w1 t)) Ry(b sin(w2 t)) Rx(c t), with its world angular velocity.
struct Motion {
  double t_s = 0.0;
  Iso3 pose() const {
    Iso3 T = Iso3::Identity();
    T.translation() = Vec3(300.0 * std::sin(2.0 * t_s), 200.0 * std::sin(3.0 * t_s + 0.4),
                           1000.0 + 150.0 * std::cos(2.5 * t_s));
    T.linear() = rotation(t_s);
    return T;
  }
  static Mat3 rotation(double t) {
    return (Eigen::AngleAxisd(1.2 * std::sin(1.5 * t), Vec3::UnitZ()) *
            Eigen::AngleAxisd(0.6 * std::sin(2.2 * t), Vec3::UnitY()) *
            Eigen::AngleAxisd(2.0 * t, Vec3::UnitX()))
        .toRotationMatrix();
  }
  Vec3 velocity() const {
    return {600.0 * std::cos(2.0 * t_s), 600.0 * std::cos(3.0 * t_s + 0.4),
            -375.0 * std::sin(2.5 * t_s)};
  }
  // World angular velocity: vee(dR/dt R^T), by a central difference of 1 us (exact to
  // ~1e-9 rad/s for this motion).
  Vec3 angular_velocity() const {
    const double h = 1e-6;
    const Mat3 dR = (rotation(t_s + h) - rotation(t_s - h)) / (2.0 * h);
    const Mat3 W = dR * rotation(t_s).transpose();
    return {0.5 * (W(2, 1) - W(1, 2)), 0.5 * (W(0, 2) - W(2, 0)), 0.5 * (W(1, 0) - W(0, 1))};
  }
};

Iso3 noisy(const Iso3& T, double pos_sd_mm, double rot_sd_rad, std::mt19937& rng) {
  std::normal_distribution<double> n(0.0, 1.0);
  const Vec3 dr(n(rng) * rot_sd_rad, n(rng) * rot_sd_rad, n(rng) * rot_sd_rad);
  Iso3 out = T;
  out.linear() = Eigen::AngleAxisd(dr.norm(), dr.norm() > 0 ? dr.normalized() : Vec3::UnitX())
                     .toRotationMatrix() *
                 T.linear();
  out.translation() += Vec3(n(rng), n(rng), n(rng)) * pos_sd_mm;
  return out;
}

struct BodyScore {
  double v_rms = 0.0, v_sd = 0.0, w_rms = 0.0, w_sd = 0.0;
  int rated = 0;
};

// 20 s of the motion with the given true noise; the filter is told stated_factor x it.
BodyScore track(double pos_sd_mm, double rot_sd_rad, double stated_factor) {
  auto filter = BodyRateFilter::create({}, 1);
  EXPECT_TRUE(filter.ok());
  std::vector<BodyMeasurement> in(1);
  std::vector<BodyRate> out = filter->make_output();
  std::mt19937 rng(11);
  double sv = 0, ssv = 0, sw = 0, ssw = 0;
  BodyScore s;
  Motion m;
  for (int k = 0; k < 2000; ++k) {
    m.t_s = k * 0.01;
    in[0] = {true, noisy(m.pose(), pos_sd_mm, rot_sd_rad, rng), pos_sd_mm * stated_factor,
             rot_sd_rad * stated_factor};
    EXPECT_TRUE(filter->update(k * kStepNs, in, out));
    if (k < 100) continue;
    EXPECT_TRUE(out[0].valid);
    sv += (out[0].v_world_mm_s - m.velocity()).squaredNorm();
    ssv += out[0].v_sd_mm_s.squaredNorm();
    sw += (out[0].w_world_rad_s - m.angular_velocity()).squaredNorm();
    ssw += out[0].w_sd_rad_s.squaredNorm();
    ++s.rated;
  }
  const double n = 3.0 * s.rated;
  s.v_rms = std::sqrt(sv / n);
  s.v_sd = std::sqrt(ssv / n);
  s.w_rms = std::sqrt(sw / n);
  s.w_sd = std::sqrt(ssw / n);
  return s;
}

TEST(BodyRates, SmoothMotionWithRightAndWrongStatedNoise) {
  // The tracker's pose noise on a hand target (0.1 mm, 0.05 deg), stated right, 4x too
  // small and 4x too large: kappa corrects the stated noise, the sd covers the error.
  for (const double factor : {1.0, 0.25, 4.0}) {
    SCOPED_TRACE(::testing::Message() << "stated x " << factor);
    const BodyScore s = track(0.1, 0.05 * kPiB / 180.0, factor);
    std::printf("stated x %.2f: v RMS %.2f mm/s (sd %.2f), w RMS %.3f deg/s (sd %.3f)\n", factor,
                s.v_rms, s.v_sd, s.w_rms * 180.0 / kPiB, s.w_sd * 180.0 / kPiB);
    EXPECT_LT(s.v_rms, 30.0);                // mm/s, at speeds up to ~900 mm/s
    EXPECT_LT(s.w_rms * 180.0 / kPiB, 5.0);  // deg/s, at up to ~250 deg/s
    EXPECT_GT(s.v_sd, 0.5 * s.v_rms);
    EXPECT_LT(s.v_sd, 2.0 * s.v_rms);
    EXPECT_GT(s.w_sd, 0.5 * s.w_rms);
    EXPECT_LT(s.w_sd, 2.0 * s.w_rms);
  }
}

TEST(BodyRates, FastSpinThroughManyTurns) {
  // 1500 deg/s about a tilted axis for 2 s (8 turns): the rotation path is continuous.
  auto filter = BodyRateFilter::create({}, 1);
  ASSERT_TRUE(filter.ok());
  std::vector<BodyMeasurement> in(1);
  std::vector<BodyRate> out = filter->make_output();
  const Vec3 axis = Vec3(1.0, 2.0, -0.5).normalized();
  const double rate = 1500.0 * kPiB / 180.0;
  for (int k = 0; k < 200; ++k) {
    Iso3 T = Iso3::Identity();
    T.linear() = Eigen::AngleAxisd(rate * k * 0.01, axis).toRotationMatrix();
    in[0] = {true, T, 0.05, 1e-3};
    ASSERT_TRUE(filter->update(k * kStepNs, in, out));
    if (k < 50) continue;
    ASSERT_TRUE(out[0].valid);
    EXPECT_LT((out[0].w_world_rad_s - rate * axis).norm(), 0.02 * rate) << "frame " << k;
    EXPECT_LT(out[0].v_world_mm_s.norm(), 5.0);
  }
}

TEST(BodyRates, WarmupGapsLostBodiesAndTimeReversal) {
  auto filter = BodyRateFilter::create({}, 2);
  ASSERT_TRUE(filter.ok());
  std::vector<BodyMeasurement> in(2);
  std::vector<BodyRate> out = filter->make_output();
  auto at = [&](int k, bool found0, bool found1) {
    for (int b = 0; b < 2; ++b) {
      Iso3 T = Iso3::Identity();
      T.translation() = Vec3(100.0 * k * 0.01 * (b + 1), 0.0, 0.0);  // 100 / 200 mm/s
      in[static_cast<std::size_t>(b)] = {b == 0 ? found0 : found1, T, 0.05, 1e-3};
    }
    return filter->update(k * kStepNs, in, out);
  };
  ASSERT_TRUE(at(0, true, true));
  EXPECT_FALSE(out[0].valid);  // warming up
  ASSERT_TRUE(at(1, true, true));
  EXPECT_FALSE(out[0].valid);
  ASSERT_TRUE(at(2, true, true));
  EXPECT_TRUE(out[0].valid);  // the third observation
  for (int k = 3; k < 40; ++k) ASSERT_TRUE(at(k, true, k < 20));
  EXPECT_NEAR(out[0].v_world_mm_s.x(), 100.0, 2.0);
  EXPECT_FALSE(out[1].valid);  // not found: no velocity, never a stale one
  EXPECT_EQ(out[1].v_world_mm_s, Vec3::Zero());
  // Body 1 back after 200 ms (> max_gap 100 ms): restarts, valid again from its 3rd pose.
  const std::uint64_t restarts = filter->counters().restarts;
  ASSERT_TRUE(at(40, true, true));
  EXPECT_EQ(filter->counters().restarts, restarts + 1);
  EXPECT_FALSE(out[1].valid);
  ASSERT_TRUE(at(41, true, true));
  ASSERT_TRUE(at(42, true, true));
  EXPECT_TRUE(out[1].valid);
  // A pose not newer than the last is skipped and counted; no velocity for it.
  ASSERT_TRUE(at(42, true, true));
  EXPECT_EQ(filter->counters().time_reversals, 2u);
  EXPECT_FALSE(out[0].valid);
  // Wrong sizes: nothing written.
  std::vector<BodyMeasurement> three(3);
  EXPECT_FALSE(filter->update(50 * kStepNs, three, out));
}

TEST(BodyRates, ConfigurationErrorsNameTheKey) {
  RateFilterConfig c;
  c.body_jerk_psd_mm2_s5 = 0.0;
  auto f = BodyRateFilter::create(c, 1);
  ASSERT_FALSE(f.ok());
  EXPECT_NE(f.error().message.find("velocity.body_jerk_psd_mm2_per_s5"), std::string::npos);
  c = RateFilterConfig{};
  c.min_position_sd_mm = -1.0;
  f = BodyRateFilter::create(c, 1);
  ASSERT_FALSE(f.ok());
  EXPECT_NE(f.error().message.find("velocity.min_position_sd_mm"), std::string::npos);
}

TEST(BodyRates, NoAllocationPerFrame) {
  auto filter = BodyRateFilter::create({}, 15);
  ASSERT_TRUE(filter.ok());
  std::vector<BodyMeasurement> in(15);
  std::vector<BodyRate> out = filter->make_output();
  Motion m;
  std::uint64_t allocations = 0;
  for (int k = 0; k < 300; ++k) {
    m.t_s = k * 0.01;
    for (auto& b : in) b = {k % 7 != 3, m.pose(), 0.1, 1e-3};
    const test::AllocationScope scope;
    filter->update(k * kStepNs, in, out);
    allocations += scope.count();
  }
  EXPECT_EQ(allocations, 0u);
}

}  // namespace
}  // namespace mocap::kinematics
