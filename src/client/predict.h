// Design: latency-compensated prediction for the consumer. predict() extrapolates the joint
// angles of one JointsMessage from its capture time to the caller's CLOCK_MONOTONIC time t
// with the message's rates (the tracker's causal constant-acceleration filter, 2027-01),
// and grows each angle's standard deviation with the rate's:
//   a(t) = a + da * dt,   sd(t)^2 = sd_a^2 + (sd_da * dt)^2,   dt = t - capture.
// It refuses (kBeyondHorizon) when |dt| exceeds the stated horizon, and predicts no joint
// whose rates are unknown (the joint is then copied, valid 0 in `predicted`). Angles are
// wrapped to (-pi, pi]. noexcept, allocation-free: callable in a 1 kHz control loop.
// Needs the quality and rates: iceoryx, or UDP datagram version 2 (v1 carries no rates).
#pragma once

#include <cstdint>

#include "client/joints_message.h"

namespace mocap::client {

enum class PredictStatus : std::uint8_t {
  kOk = 0,             // every joint with known rates predicted
  kNoMessage = 1,      // the message carries no joints
  kBeyondHorizon = 2,  // |t - capture| over the horizon: nothing predicted
};

struct PredictedJoint {
  std::uint8_t valid = 0;  // 1: predicted (the joint was valid with known rates)
  std::uint8_t reserved[3] = {0, 0, 0};
  float a_rad[3] = {0.0f, 0.0f, 0.0f};   // angles at t (hinge: index 0)
  float sd_rad[3] = {0.0f, 0.0f, 0.0f};  // their standard deviations at t
};

struct JointPrediction {
  std::int64_t t_ns = 0;  // the time predicted to (CLOCK_MONOTONIC)
  double dt_s = 0.0;      // t - capture of the message used
  std::uint16_t joint_count = 0;
  PredictedJoint joints[kMaxJoints];
};

inline constexpr double kDefaultPredictHorizonS = 0.05;  // 5 frames at 100 fps

PredictStatus predict(const JointsMessage& msg, std::int64_t t_ns, JointPrediction& out,
                      double horizon_s = kDefaultPredictHorizonS) noexcept;

}  // namespace mocap::client
