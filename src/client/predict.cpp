// Design: see predict.h.
#include "client/predict.h"

#include <cmath>

namespace mocap::client {
namespace {

constexpr double kPi = 3.14159265358979323846;

double wrap_pi(double a) noexcept {
  a = std::remainder(a, 2.0 * kPi);  // [-pi, pi]
  return a <= -kPi ? a + 2.0 * kPi : a;
}

}  // namespace

PredictStatus predict(const JointsMessage& msg, std::int64_t t_ns, JointPrediction& out,
                      double horizon_s) noexcept {
  out.t_ns = t_ns;
  out.dt_s = static_cast<double>(t_ns - msg.capture_ns) * 1e-9;
  out.joint_count = msg.joint_count > kMaxJoints ? kMaxJoints : msg.joint_count;
  for (std::uint16_t j = 0; j < kMaxJoints; ++j) out.joints[j] = PredictedJoint{};
  if (out.joint_count == 0) return PredictStatus::kNoMessage;
  if (!(std::abs(out.dt_s) <= horizon_s)) return PredictStatus::kBeyondHorizon;
  const double dt = out.dt_s;
  for (std::uint16_t j = 0; j < out.joint_count; ++j) {
    const JointRecord& r = msg.joints[j];
    const JointRates& rt = msg.rates[j];
    PredictedJoint& p = out.joints[j];
    const bool known = r.valid && rt.valid;
    const int dofs = r.type == static_cast<std::uint8_t>(JointKind::kHinge) ? 1 : 3;
    for (int k = 0; k < 3; ++k) {
      p.a_rad[k] = r.a[k];
      p.sd_rad[k] = msg.quality[j].sd_rad[k];
      if (!known || k >= dofs) continue;
      const double a = static_cast<double>(r.a[k]) + static_cast<double>(rt.rate_rad_s[k]) * dt;
      const double sd_a = static_cast<double>(msg.quality[j].sd_rad[k]);
      const double sd_v = static_cast<double>(rt.sd_rad_s[k]) * dt;
      p.a_rad[k] = static_cast<float>(wrap_pi(a));
      p.sd_rad[k] = static_cast<float>(std::sqrt(sd_a * sd_a + sd_v * sd_v));
    }
    p.valid = known ? 1 : 0;
  }
  return PredictStatus::kOk;
}

}  // namespace mocap::client
