// Design: see body_rates.h.
#include "kinematics/body_rates.h"

#include <algorithm>
#include <cmath>

namespace mocap::kinematics {
namespace {

constexpr double kInitialSpeedSdMmPerS = 5000.0;  // unknown at a restart
constexpr double kInitialAccelSdMmPerS2 = 1.0e5;  // unknown at a restart
constexpr double kInitialTurnSdRadPerS = 20.0;    // as a joint's rate
constexpr double kInitialTurnAccelSdRadPerS2 = 500.0;

// The rotation vector of q (angle in [0, pi], about the axis of q with qw >= 0).
Vec3 rotation_vector(Quat q) noexcept {
  if (q.w() < 0.0) q.coeffs() = -q.coeffs();
  const Vec3 v = q.vec();
  const double s = v.norm();
  if (s < 1e-12) return 2.0 * v;  // first order: angle ~ 2 |v|
  return (2.0 * std::atan2(s, q.w()) / s) * v;
}

}  // namespace

Expected<BodyRateFilter> BodyRateFilter::create(const RateFilterConfig& config,
                                                std::size_t bodies) {
  if (auto ok = check_rate_config(config); !ok) return ok.error();
  BodyRateFilter f;
  f.config_ = config;
  f.bodies_.resize(bodies);
  return f;
}

void BodyRateFilter::reset() noexcept {
  for (Body& b : bodies_) b = Body{};
  counters_ = RateFilterCounters{};
}

double BodyRateFilter::position_variance(const BodyMeasurement& m) const noexcept {
  const double sd = std::isfinite(m.position_sd_mm)
                        ? std::max(m.position_sd_mm, config_.min_position_sd_mm)
                        : config_.min_position_sd_mm;
  return sd * sd;
}

double BodyRateFilter::rotation_variance(const BodyMeasurement& m) const noexcept {
  const double sd = std::isfinite(m.rotation_sd_rad)
                        ? std::max(m.rotation_sd_rad, config_.min_angle_sd_rad)
                        : config_.min_angle_sd_rad;
  return sd * sd;
}

void BodyRateFilter::restart(Body& body, const BodyMeasurement& m, std::int64_t t_ns) noexcept {
  ++counters_.restarts;
  body.clock.restart(t_ns);
  const Vec3 t = m.T_world_body.translation();
  const double vp = position_variance(m), vr = rotation_variance(m);
  // The rotation path starts where it left off: only its differences matter.
  for (int k = 0; k < 3; ++k) {
    body.axis[static_cast<std::size_t>(k)].restart(t[k], vp, kInitialSpeedSdMmPerS,
                                                   kInitialAccelSdMmPerS2);
    body.axis[static_cast<std::size_t>(3 + k)].restart(body.z_rot_rad[k], vr, kInitialTurnSdRadPerS,
                                                       kInitialTurnAccelSdRadPerS2);
  }
  body.q_last = Quat(m.T_world_body.linear());
}

void BodyRateFilter::step(Body& body, const BodyMeasurement& m, std::int64_t t_ns,
                          BodyRate& out) noexcept {
  const CaStep s = body.clock.advance(t_ns);
  const Vec3 t = m.T_world_body.translation();
  const Quat q(m.T_world_body.linear());
  body.z_rot_rad += rotation_vector(q * body.q_last.conjugate());
  body.q_last = q;
  const double vp = position_variance(m), vr = rotation_variance(m);
  for (int k = 0; k < 3; ++k) {
    CaAxis& p = body.axis[static_cast<std::size_t>(k)];
    p.step(s, config_.body_jerk_psd_mm2_s5, t[k] - p.predicted_value(s.dt_s), vp);
    out.v_world_mm_s[k] = p.x[1];
    out.v_sd_mm_s[k] = p.rate_sd();
    CaAxis& r = body.axis[static_cast<std::size_t>(3 + k)];
    r.step(s, config_.jerk_psd_rad2_s5, body.z_rot_rad[k] - r.predicted_value(s.dt_s), vr);
    out.w_world_rad_s[k] = r.x[1];
    out.w_sd_rad_s[k] = r.rate_sd();
  }
}

bool BodyRateFilter::update(std::int64_t t_ns, std::span<const BodyMeasurement> bodies,
                            std::span<BodyRate> out) noexcept {
  if (bodies.size() != bodies_.size() || out.size() != bodies_.size()) return false;
  const auto max_gap_ns = static_cast<std::int64_t>(config_.max_gap_s * 1e9);
  for (std::size_t i = 0; i < bodies_.size(); ++i) {
    Body& b = bodies_[i];
    const BodyMeasurement& m = bodies[i];
    BodyRate& r = out[i];
    r = BodyRate{};
    if (!m.found) continue;
    if (b.clock.active && t_ns <= b.clock.t_last_ns) {
      ++counters_.time_reversals;
      continue;
    }
    if (!b.clock.active || t_ns - b.clock.t_last_ns > max_gap_ns) {
      restart(b, m, t_ns);
    } else {
      step(b, m, t_ns, r);
    }
    if (b.clock.observations < config_.warmup_observations) {
      r = BodyRate{};
      continue;
    }
    r.valid = true;
  }
  return true;
}

}  // namespace mocap::kinematics
