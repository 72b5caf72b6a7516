// Design: see joint_rates.h. One CaAxis (ca_filter.h) per degree of freedom, one CaClock
// per joint.
#include "kinematics/joint_rates.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>

namespace mocap::kinematics {
namespace {

constexpr double kPi = std::numbers::pi;
constexpr double kInitialRateSdRadPerS = 20.0;     // ~1150 deg/s: unknown at a restart
constexpr double kInitialAccelSdRadPerS2 = 500.0;  // unknown at a restart

double wrap_pi(double a) noexcept {
  if (a > kPi || a <= -kPi) a -= 2.0 * kPi * std::floor((a + kPi) / (2.0 * kPi));
  if (a <= -kPi) a += 2.0 * kPi;
  return a;
}

double angle_of(const JointAngle& a, int k) noexcept {
  return k == 0 ? a.a0 : (k == 1 ? a.a1 : a.a2);
}

}  // namespace

Expected<void> check_rate_config(const RateFilterConfig& config) {
  const auto positive = [](double v) { return std::isfinite(v) && v > 0.0; };
  if (!positive(config.max_gap_s))
    return Error{"velocity.max_gap_ms: must be a positive number of milliseconds"};
  if (!positive(config.jerk_psd_rad2_s5))
    return Error{"velocity.jerk_psd_deg2_per_s5: must be positive"};
  if (!positive(config.body_jerk_psd_mm2_s5))
    return Error{"velocity.body_jerk_psd_mm2_per_s5: must be positive"};
  if (!positive(config.min_angle_sd_rad))
    return Error{"velocity.min_angle_sd_deg: must be positive"};
  if (!positive(config.min_position_sd_mm))
    return Error{"velocity.min_position_sd_mm: must be positive"};
  if (config.warmup_observations < 1 || config.warmup_observations > 100)
    return Error{"velocity.warmup_frames: must be 1..100, not " +
                 std::to_string(config.warmup_observations)};
  return {};
}

Expected<JointRateFilter> JointRateFilter::create(const RateFilterConfig& config,
                                                  const std::vector<JointType>& types) {
  if (auto ok = check_rate_config(config); !ok) return ok.error();
  JointRateFilter f;
  f.config_ = config;
  f.joints_.resize(types.size());
  for (std::size_t i = 0; i < types.size(); ++i)
    f.joints_[i].dofs = types[i] == JointType::kHinge ? 1 : 3;
  return f;
}

void JointRateFilter::reset() noexcept {
  for (Joint& j : joints_) {
    const int dofs = j.dofs;
    j = Joint{};
    j.dofs = dofs;
  }
  counters_ = RateFilterCounters{};
}

double JointRateFilter::stated_variance(const JointAngle& a, int k) const noexcept {
  const double sd = a.sd_rad[static_cast<std::size_t>(k)];
  const double s =
      std::isfinite(sd) ? std::max(sd, config_.min_angle_sd_rad) : config_.min_angle_sd_rad;
  return s * s;
}

void JointRateFilter::restart(Joint& j, const JointAngle& a, std::int64_t t_ns) noexcept {
  ++counters_.restarts;
  j.clock.restart(t_ns);
  for (int k = 0; k < j.dofs; ++k)
    j.dof[static_cast<std::size_t>(k)].restart(angle_of(a, k), stated_variance(a, k),
                                               kInitialRateSdRadPerS, kInitialAccelSdRadPerS2);
}

void JointRateFilter::step(Joint& j, JointAngle& a, std::int64_t t_ns) noexcept {
  const CaStep s = j.clock.advance(t_ns);
  for (int k = 0; k < j.dofs; ++k) {
    const auto uk = static_cast<std::size_t>(k);
    CaAxis& d = j.dof[uk];
    // The innovation made continuous with the state (angles wrap, the state does not).
    const double y = wrap_pi(angle_of(a, k) - d.predicted_value(s.dt_s));
    d.step(s, config_.jerk_psd_rad2_s5, y, stated_variance(a, k));
    a.rate_rad_s[uk] = d.x[1];
    a.rate_sd_rad_s[uk] = d.rate_sd();
  }
}

bool JointRateFilter::update(std::int64_t t_ns, JointAngles& angles) noexcept {
  if (angles.joints.size() != joints_.size()) return false;
  const auto max_gap_ns = static_cast<std::int64_t>(config_.max_gap_s * 1e9);
  for (std::size_t i = 0; i < joints_.size(); ++i) {
    Joint& j = joints_[i];
    JointAngle& a = angles.joints[i];
    a.rate_valid = false;
    a.rate_rad_s = {0.0, 0.0, 0.0};
    a.rate_sd_rad_s = {0.0, 0.0, 0.0};
    if (!a.valid) continue;
    if (j.clock.active && t_ns <= j.clock.t_last_ns) {
      ++counters_.time_reversals;
      continue;
    }
    if (!j.clock.active || t_ns - j.clock.t_last_ns > max_gap_ns) {
      restart(j, a, t_ns);
    } else {
      step(j, a, t_ns);
    }
    if (j.clock.observations < config_.warmup_observations) {
      a.rate_rad_s = {0.0, 0.0, 0.0};
      a.rate_sd_rad_s = {0.0, 0.0, 0.0};
      continue;
    }
    a.rate_valid = true;
  }
  return true;
}

}  // namespace mocap::kinematics
