// Design: see joint_rates.h. The filter of one degree of freedom is written out on the
// six numbers of its symmetric covariance (no Eigen temporaries: it runs 42 times a frame
// on the humanoid, inside the identify thread's budget).
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
constexpr double kNisTimeConstantS = 0.3;          // running mean of the NIS
constexpr double kLambdaGainPerS = 5.0;            // d ln(lambda)/dt per unit of NIS excess
constexpr double kKappaTimeConstantS = 1.0;        // running mean of the noise ratio
constexpr double kMaxNisSample = 25.0;             // one outlier moves the means this much
constexpr double kMaxRatioSample = 100.0;
constexpr double kLambdaMin = 1e-2, kLambdaMax = 1e3;
constexpr double kKappaMin = 0.25, kKappaMax = 400.0;
constexpr double kAdaptMaxStepS = 0.05;    // a long step adapts as this one at most
constexpr double kSpacingTolerance = 0.1;  // third differences need equally spaced angles

double wrap_pi(double a) noexcept {
  if (a > kPi || a <= -kPi) a -= 2.0 * kPi * std::floor((a + kPi) / (2.0 * kPi));
  if (a <= -kPi) a += 2.0 * kPi;
  return a;
}

double angle_of(const JointAngle& a, int k) noexcept {
  return k == 0 ? a.a0 : (k == 1 ? a.a1 : a.a2);
}

}  // namespace

Expected<JointRateFilter> JointRateFilter::create(const RateFilterConfig& config,
                                                  const std::vector<JointType>& types) {
  const auto positive = [](double v) { return std::isfinite(v) && v > 0.0; };
  if (!positive(config.max_gap_s))
    return Error{"velocity.max_gap_ms: must be a positive number of milliseconds"};
  if (!positive(config.jerk_psd_rad2_s5))
    return Error{"velocity.jerk_psd_deg2_per_s5: must be positive"};
  if (!positive(config.min_angle_sd_rad))
    return Error{"velocity.min_angle_sd_deg: must be positive"};
  if (config.warmup_observations < 1 || config.warmup_observations > 100)
    return Error{"velocity.warmup_frames: must be 1..100, not " +
                 std::to_string(config.warmup_observations)};
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
  j.active = true;
  j.observations = 1;
  j.t_last_ns = t_ns;
  j.hist = 1;
  j.t_hist[0] = t_ns;
  for (int k = 0; k < j.dofs; ++k) {
    Dof& d = j.dof[static_cast<std::size_t>(k)];
    const double v = stated_variance(a, k);
    // The noise scales are kept: they describe the joint's measurement and motion, which
    // a short loss of sight does not change.
    const double z = angle_of(a, k);
    d.x = {z, 0.0, 0.0};
    d.P = {v * d.kappa, 0.0,
           0.0,         kInitialRateSdRadPerS * kInitialRateSdRadPerS,
           0.0,         kInitialAccelSdRadPerS2 * kInitialAccelSdRadPerS2};
    d.z[0] = z;
    d.v[0] = v;
  }
}

void JointRateFilter::step(Joint& j, JointAngle& a, std::int64_t t_ns) noexcept {
  const double dt = static_cast<double>(t_ns - j.t_last_ns) * 1e-9;
  const double h = 0.5 * dt * dt;
  // Equally spaced history (for the third differences): shift it, or restart it.
  bool equal_spacing = false;
  if (j.hist == 4) {
    for (int i = 0; i < 3; ++i) j.t_hist[static_cast<std::size_t>(i)] = j.t_hist[i + 1u];
  }
  const int slot = std::min(j.hist, 3);
  j.t_hist[static_cast<std::size_t>(slot)] = t_ns;
  const int n = slot + 1;
  if (n == 4) {
    const double s0 = static_cast<double>(j.t_hist[1] - j.t_hist[0]);
    const double s1 = static_cast<double>(j.t_hist[2] - j.t_hist[1]);
    const double s2 = static_cast<double>(j.t_hist[3] - j.t_hist[2]);
    const double mean = (s0 + s1 + s2) / 3.0;
    const double tol = kSpacingTolerance * mean;
    equal_spacing =
        std::abs(s0 - mean) <= tol && std::abs(s1 - mean) <= tol && std::abs(s2 - mean) <= tol;
  }
  const double adapt_dt = std::min(dt, kAdaptMaxStepS);
  const double a_nis = std::min(1.0, adapt_dt / kNisTimeConstantS);
  const double a_kappa = std::min(1.0, adapt_dt / kKappaTimeConstantS);

  for (int k = 0; k < j.dofs; ++k) {
    Dof& d = j.dof[static_cast<std::size_t>(k)];
    // Predict: x = F x, P = F P F^T + q Q(dt).
    auto& x = d.x;
    auto& P = d.P;
    x[0] += dt * x[1] + h * x[2];
    x[1] += dt * x[2];
    const double r00 = P[0] + dt * P[1] + h * P[2], r01 = P[1] + dt * P[3] + h * P[4],
                 r02 = P[2] + dt * P[4] + h * P[5];
    const double r11 = P[3] + dt * P[4], r12 = P[4] + dt * P[5];
    const double q = config_.jerk_psd_rad2_s5 * d.lambda;
    const double dt2 = dt * dt, dt3 = dt2 * dt;
    P[0] = r00 + dt * r01 + h * r02 + q * dt3 * dt2 / 20.0;
    P[1] = r01 + dt * r02 + q * dt2 * dt2 / 8.0;
    P[2] = r02 + q * dt3 / 6.0;
    P[3] = r11 + dt * r12 + q * dt3 / 3.0;
    P[4] = r12 + q * dt2 / 2.0;
    P[5] = P[5] + q * dt;

    // Update with the angle, made continuous with the state.
    const double v = stated_variance(a, k);
    const double R = v * d.kappa;
    const double y = wrap_pi(angle_of(a, k) - x[0]);
    const double z = x[0] + y;
    const double S = P[0] + R;
    const double k0 = P[0] / S, k1 = P[1] / S, k2 = P[2] / S;
    x[0] += k0 * y;
    x[1] += k1 * y;
    x[2] += k2 * y;
    const double p00 = P[0], p01 = P[1], p02 = P[2];
    P[0] = p00 - k0 * p00;
    P[1] = p01 - k0 * p01;
    P[2] = p02 - k0 * p02;
    P[3] -= k1 * p01;
    P[4] -= k1 * p02;
    P[5] -= k2 * p02;

    // Process-noise scale from the innovations.
    d.nis_mean += a_nis * (std::min(y * y / S, kMaxNisSample) - d.nis_mean);
    d.lambda = std::clamp(d.lambda * std::exp(kLambdaGainPerS * (d.nis_mean - 1.0) * adapt_dt),
                          kLambdaMin, kLambdaMax);

    // Measurement-noise scale from the third difference of equally spaced angles.
    if (j.hist == 4) {
      for (int i = 0; i < 3; ++i) {
        d.z[static_cast<std::size_t>(i)] = d.z[i + 1u];
        d.v[static_cast<std::size_t>(i)] = d.v[i + 1u];
      }
    }
    d.z[static_cast<std::size_t>(slot)] = z;
    d.v[static_cast<std::size_t>(slot)] = v;
    if (equal_spacing) {
      const double d3 = d.z[3] - 3.0 * d.z[2] + 3.0 * d.z[1] - d.z[0];
      const double var3 = d.v[0] + 9.0 * d.v[1] + 9.0 * d.v[2] + d.v[3];
      const double ratio = std::min(d3 * d3 / var3, kMaxRatioSample);
      d.kappa = std::clamp(d.kappa + a_kappa * (ratio - d.kappa), kKappaMin, kKappaMax);
    }

    a.rate_rad_s[static_cast<std::size_t>(k)] = x[1];
    a.rate_sd_rad_s[static_cast<std::size_t>(k)] = std::sqrt(std::max(P[3], 0.0));
  }
  j.hist = n;
  j.t_last_ns = t_ns;
  ++j.observations;
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
    if (j.active && t_ns <= j.t_last_ns) {
      ++counters_.time_reversals;
      continue;
    }
    if (!j.active || t_ns - j.t_last_ns > max_gap_ns) {
      restart(j, a, t_ns);
    } else {
      step(j, a, t_ns);
    }
    if (j.observations < config_.warmup_observations) {
      a.rate_rad_s = {0.0, 0.0, 0.0};
      a.rate_sd_rad_s = {0.0, 0.0, 0.0};
      continue;
    }
    a.rate_valid = true;
  }
  return true;
}

}  // namespace mocap::kinematics
