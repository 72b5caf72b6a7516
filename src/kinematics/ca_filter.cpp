// Design: see ca_filter.h. The constants are the adaptation's time scales and bounds
// (docs/kinematics.md, "Joint rates").
#include "kinematics/ca_filter.h"

#include <algorithm>
#include <cmath>

namespace mocap::kinematics {
namespace {

constexpr double kNisTimeConstantS = 0.3;    // running mean of the NIS
constexpr double kLambdaGainPerS = 5.0;      // d ln(lambda)/dt per unit of NIS excess
constexpr double kKappaTimeConstantS = 1.0;  // running mean of the noise ratio
constexpr double kMaxNisSample = 25.0;       // one outlier moves the means this much
constexpr double kMaxRatioSample = 100.0;
constexpr double kLambdaMin = 1e-2, kLambdaMax = 1e3;
constexpr double kKappaMin = 0.25, kKappaMax = 400.0;
constexpr double kAdaptMaxStepS = 0.05;    // a long step adapts as this one at most
constexpr double kSpacingTolerance = 0.1;  // third differences need equally spaced samples

}  // namespace

void CaClock::restart(std::int64_t t_ns) noexcept {
  active = true;
  observations = 1;
  t_last_ns = t_ns;
  hist = 1;
  t_hist[0] = t_ns;
}

CaStep CaClock::advance(std::int64_t t_ns) noexcept {
  CaStep s;
  s.dt_s = static_cast<double>(t_ns - t_last_ns) * 1e-9;
  s.shift = hist == 4;
  if (s.shift) {
    for (std::size_t i = 0; i < 3; ++i) t_hist[i] = t_hist[i + 1];
  }
  s.slot = std::min(hist, 3);
  t_hist[static_cast<std::size_t>(s.slot)] = t_ns;
  const int n = s.slot + 1;
  if (n == 4) {
    const double s0 = static_cast<double>(t_hist[1] - t_hist[0]);
    const double s1 = static_cast<double>(t_hist[2] - t_hist[1]);
    const double s2 = static_cast<double>(t_hist[3] - t_hist[2]);
    const double mean = (s0 + s1 + s2) / 3.0;
    const double tol = kSpacingTolerance * mean;
    s.equal_spacing =
        std::abs(s0 - mean) <= tol && std::abs(s1 - mean) <= tol && std::abs(s2 - mean) <= tol;
  }
  const double adapt_dt = std::min(s.dt_s, kAdaptMaxStepS);
  s.a_nis = std::min(1.0, adapt_dt / kNisTimeConstantS);
  s.a_kappa = std::min(1.0, adapt_dt / kKappaTimeConstantS);
  hist = n;
  t_last_ns = t_ns;
  ++observations;
  return s;
}

void CaAxis::restart(double z0, double v0, double rate_sd, double accel_sd) noexcept {
  x = {z0, 0.0, 0.0};
  P = {v0 * kappa, 0.0, 0.0, rate_sd * rate_sd, 0.0, accel_sd * accel_sd};
  z[0] = z0;
  v[0] = v0;
}

double CaAxis::rate_sd() const noexcept { return std::sqrt(std::max(P[3], 0.0)); }

void CaAxis::step(const CaStep& s, double q_base, double y_in, double v0) noexcept {
  const double dt = s.dt_s;
  const double h = 0.5 * dt * dt;
  // Predict: x = F x, P = F P F^T + q Q(dt).
  x[0] += dt * x[1] + h * x[2];
  x[1] += dt * x[2];
  const double r00 = P[0] + dt * P[1] + h * P[2], r01 = P[1] + dt * P[3] + h * P[4],
               r02 = P[2] + dt * P[4] + h * P[5];
  const double r11 = P[3] + dt * P[4], r12 = P[4] + dt * P[5];
  const double q = q_base * lambda;
  const double dt2 = dt * dt, dt3 = dt2 * dt;
  P[0] = r00 + dt * r01 + h * r02 + q * dt3 * dt2 / 20.0;
  P[1] = r01 + dt * r02 + q * dt2 * dt2 / 8.0;
  P[2] = r02 + q * dt3 / 6.0;
  P[3] = r11 + dt * r12 + q * dt3 / 3.0;
  P[4] = r12 + q * dt2 / 2.0;
  P[5] = P[5] + q * dt;

  // Update with the measurement z = x[0] + y.
  const double y = y_in;
  const double zc = x[0] + y;
  const double R = v0 * kappa;
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
  const double adapt_dt = std::min(dt, kAdaptMaxStepS);
  nis_mean += s.a_nis * (std::min(y * y / S, kMaxNisSample) - nis_mean);
  lambda = std::clamp(lambda * std::exp(kLambdaGainPerS * (nis_mean - 1.0) * adapt_dt), kLambdaMin,
                      kLambdaMax);

  // Measurement-noise scale from the third difference of equally spaced measurements.
  if (s.shift) {
    for (std::size_t i = 0; i < 3; ++i) {
      z[i] = z[i + 1];
      v[i] = v[i + 1];
    }
  }
  z[static_cast<std::size_t>(s.slot)] = zc;
  v[static_cast<std::size_t>(s.slot)] = v0;
  if (s.equal_spacing) {
    const double d3 = z[3] - 3.0 * z[2] + 3.0 * z[1] - z[0];
    const double var3 = v[0] + 9.0 * v[1] + 9.0 * v[2] + v[3];
    const double ratio = std::min(d3 * d3 / var3, kMaxRatioSample);
    kappa = std::clamp(kappa + s.a_kappa * (ratio - kappa), kKappaMin, kKappaMax);
  }
}

}  // namespace mocap::kinematics
