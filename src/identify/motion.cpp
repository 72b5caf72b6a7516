// Design: see motion.h. The SE(3) exponential and logarithm use the closed forms with
// the V matrix, V = I + B [w]x + C [w]x^2, B = (1 - cos th) / th^2, C = (th - sin th) / th^3,
// and their Taylor series below th = 1e-4 rad (no division by a vanishing angle).
#include "identify/motion.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "core/units.h"
#include "identify/consistency.h"

namespace mocap {
namespace {
constexpr double kSmallAngle = 1e-4;

Mat3 hat(const Vec3& w) {
  Mat3 W;
  W << 0.0, -w.z(), w.y(), w.z(), 0.0, -w.x(), -w.y(), w.x(), 0.0;
  return W;
}

Mat3 v_matrix(const Vec3& w) {
  const double th = w.norm();
  const Mat3 W = hat(w);
  const double B = th < kSmallAngle ? 0.5 - th * th / 24.0 : (1.0 - std::cos(th)) / (th * th);
  const double C =
      th < kSmallAngle ? 1.0 / 6.0 - th * th / 120.0 : (th - std::sin(th)) / (th * th * th);
  return Mat3::Identity() + B * W + C * W * W;
}

Mat3 v_inverse(const Vec3& w) {
  const double th = w.norm();
  const Mat3 W = hat(w);
  // V^-1 = I - W/2 + D W^2, D = (1 - A / (2B)) / th^2, A = sin th / th.
  double D = 1.0 / 12.0 + th * th / 720.0;
  if (th >= kSmallAngle) {
    const double A = std::sin(th) / th;
    const double B = (1.0 - std::cos(th)) / (th * th);
    D = (1.0 - A / (2.0 * B)) / (th * th);
  }
  return Mat3::Identity() - 0.5 * W + D * W * W;
}

double seconds(std::int64_t ns) { return static_cast<double>(ns) * 1e-9; }
}  // namespace

void se3_log(const Iso3& T, Vec3& w, Vec3& v) noexcept {
  const Eigen::AngleAxisd aa(T.linear());
  w = aa.angle() * aa.axis();
  v = v_inverse(w) * T.translation();
}

Iso3 se3_exp(const Vec3& w, const Vec3& v) noexcept {
  Iso3 T = Iso3::Identity();
  const double th = w.norm();
  T.linear() = th < 1e-12 ? Mat3::Identity() : Eigen::AngleAxisd(th, w / th).toRotationMatrix();
  T.translation() = v_matrix(w) * v;
  return T;
}

MotionBounds::MotionBounds(const IdentifyConfig& c) noexcept
    : constant_velocity_(c.motion_model == MotionModel::kConstantVelocity),
      v_max_(c.max_speed_mm_per_s > 0.0 ? c.max_speed_mm_per_s : 0.0),
      w_max_(c.max_angular_speed_deg_per_s > 0.0 ? c.max_angular_speed_deg_per_s * kRadPerDeg
                                                 : 0.0),
      q_(std::sqrt(chi2_quantile(3, c.consistency_confidence))),
      sigma2_(c.point_sigma_mm * c.point_sigma_mm),
      legacy_gate_mm_(c.warm_gate_mm) {
  accel_ = c.max_acceleration_mm_per_s2 > 0.0 ? c.max_acceleration_mm_per_s2 : v_max_ * w_max_;
}

PoseNoise MotionBounds::pose_noise(const TargetModel& model,
                                   const std::array<std::int16_t, kMaxMarkers>& pm) const noexcept {
  PoseNoise n;
  int m = 0;
  Vec3 centroid = Vec3::Zero();
  for (int c = 0; c < model.k; ++c) {
    if (pm[static_cast<std::size_t>(c)] < 0) continue;
    centroid += model.M_body[static_cast<std::size_t>(c)];
    ++m;
  }
  if (m == 0 || sigma2_ == 0.0) return n;
  centroid /= m;
  Mat3 J = Mat3::Zero();
  for (int c = 0; c < model.k; ++c) {
    if (pm[static_cast<std::size_t>(c)] < 0) continue;
    const Vec3 q = model.M_body[static_cast<std::size_t>(c)] - centroid;
    J += q.squaredNorm() * Mat3::Identity() - q * q.transpose();
  }
  Mat3 J_inv;
  bool invertible = false;
  J.computeInverseWithCheck(J_inv, invertible, 1e-12 * J.trace() * J.trace() * J.trace());
  if (!invertible) {  // collinear: the rotation about the line is not measured at all
    n.marker_var_mm2.fill(std::numeric_limits<double>::infinity());
    n.angle_var_rad2 = std::numeric_limits<double>::infinity();
    return n;
  }
  const double tr = J_inv.trace();
  n.angle_var_rad2 = sigma2_ * tr;
  for (int c = 0; c < model.k; ++c) {
    const Vec3 q = model.M_body[static_cast<std::size_t>(c)] - centroid;
    n.marker_var_mm2[static_cast<std::size_t>(c)] =
        sigma2_ * (3.0 / m + q.squaredNorm() * tr - q.dot(J_inv * q));
  }
  return n;
}

Iso3 MotionBounds::predict(const MotionTrack& tr, std::int64_t t_ns) const noexcept {
  if (!constant_velocity_ || !tr.has_prev || tr.t_last_ns <= tr.t_prev_ns) return tr.T_last;
  const double r =
      static_cast<double>(t_ns - tr.t_last_ns) / static_cast<double>(tr.t_last_ns - tr.t_prev_ns);
  Vec3 w, v;
  se3_log(tr.T_last * tr.T_prev.inverse(), w, v);
  return se3_exp(r * w, r * v) * tr.T_last;
}

void MotionBounds::gates_mm(const MotionTrack& tr, std::int64_t t_ns, const TargetModel& model,
                            std::array<double, kMaxMarkers>& gate) const noexcept {
  const double age_s = seconds(t_ns - tr.t_last_ns);
  const double interval_s = tr.has_prev ? seconds(tr.t_last_ns - tr.t_prev_ns) : 0.0;
  const bool cv = constant_velocity_ && tr.has_prev && interval_s > 0.0;
  const double cap = 0.5 * model.min_pair_mm;
  double motion = 0.0, w_last = 1.0, w_prev = 0.0;  // extrapolation weights of the poses
  if (cv && (accel_ > 0.0 || v_max_ > 0.0)) {
    const double r = age_s / interval_s;
    motion = accel_ > 0.0 ? 0.5 * accel_ * age_s * (age_s + interval_s) : 1e300;
    if (v_max_ > 0.0) motion = std::min(motion, 2.0 * v_max_ * age_s);
    w_last = (1.0 + r) * (1.0 + r);
    w_prev = r * r;
  } else if (!cv && v_max_ > 0.0) {
    motion = v_max_ * age_s;
  } else {  // no stated bound of the motion: the configured gate, scaled by the age
    const double interval = interval_s > 0.0 ? interval_s : age_s;
    const double g =
        legacy_gate_mm_ * (interval > 0.0 && age_s > interval ? age_s / interval : 1.0);
    gate.fill(std::min(g, cap));
    return;
  }
  for (int c = 0; c < model.k; ++c) {
    const auto cs = static_cast<std::size_t>(c);
    double var = w_last * tr.noise_last.marker_var_mm2[cs] + 3.0 * sigma2_;
    if (w_prev > 0.0) var += w_prev * tr.noise_prev.marker_var_mm2[cs];
    gate[cs] = std::min(motion + q_ * std::sqrt(var), cap);
  }
}

bool MotionBounds::within_limits(const MotionTrack& tr, const Iso3& T, const PoseNoise& now,
                                 std::int64_t t_ns, const TargetModel& model) const noexcept {
  if (!tr.valid) return true;
  const double dt_s = seconds(t_ns - tr.t_last_ns);
  if (!(dt_s > 0.0)) return true;
  if (v_max_ > 0.0) {
    for (int c = 0; c < model.k; ++c) {
      const auto cs = static_cast<std::size_t>(c);
      const double limit =
          v_max_ * dt_s + q_ * std::sqrt(tr.noise_last.marker_var_mm2[cs] + now.marker_var_mm2[cs]);
      const Vec3& M = model.M_body[cs];
      if (!((T * M - tr.T_last * M).norm() <= limit)) return false;
    }
  }
  if (w_max_ > 0.0) {
    const Eigen::AngleAxisd dR(T.linear() * tr.T_last.linear().transpose());
    const double limit =
        w_max_ * dt_s + q_ * std::sqrt(tr.noise_last.angle_var_rad2 + now.angle_var_rad2);
    if (!(std::abs(dR.angle()) <= limit)) return false;
  }
  return true;
}

}  // namespace mocap
