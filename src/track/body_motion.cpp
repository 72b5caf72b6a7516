// Design: see body_motion.h.
#include "track/body_motion.h"

#include <algorithm>
#include <cmath>

namespace mocap {

Expected<BodyMotion> BodyMotion::create(const TargetSet& targets, double point_sigma_mm,
                                        const kinematics::RateFilterConfig& config) {
  if (!(std::isfinite(point_sigma_mm) && point_sigma_mm > 0.0))
    return Error{"identification.point_sigma_mm: must be positive for body velocities"};
  auto filter = kinematics::BodyRateFilter::create(config, targets.bodies.size());
  if (!filter) return filter.error();
  BodyMotion m(std::move(filter).value());
  m.sigma_mm_ = point_sigma_mm;
  for (const MarkerTarget& body : targets.bodies) {
    Geometry g;
    g.markers = static_cast<int>(body.markers_body.size());
    Vec3 c = Vec3::Zero();
    for (const Vec3& p : body.markers_body) c += p;
    if (g.markers > 0) c /= g.markers;
    Mat3 J = Mat3::Zero();
    for (const Vec3& p : body.markers_body) {
      const Vec3 d = p - c;
      J += d.squaredNorm() * Mat3::Identity() - d * d.transpose();
    }
    // A target whose markers lie on a line (or fewer than 3) has no rotation information
    // about that line: its stated noise is then large, and the filter's kappa decides.
    const Eigen::LDLT<Mat3> ldlt(J);
    const bool ok = g.markers >= 3 && ldlt.info() == Eigen::Success && J.determinant() > 1e-9;
    g.rotation_var_rad2 = ok ? ldlt.solve(Mat3::Identity()).trace() / 3.0 : 1.0;
    g.lever_mm = c.norm();
    m.geometry_.push_back(g);
  }
  m.measured_.resize(targets.bodies.size());
  return m;
}

bool BodyMotion::update(std::int64_t t_ns, const BodyPoses& poses,
                        std::span<kinematics::BodyRate> out) noexcept {
  const std::size_t n = std::min(measured_.size(), static_cast<std::size_t>(poses.count));
  const double s2 = sigma_mm_ * sigma_mm_;
  for (std::size_t b = 0; b < measured_.size(); ++b) {
    kinematics::BodyMeasurement& m = measured_[b];
    m.found = b < n && poses.bodies[b].found;
    if (!m.found) continue;
    const BodyPose& pose = poses.bodies[b];
    const Geometry& g = geometry_[b];
    const double matched = std::max(1, pose.markers);
    const double rot_var = s2 * g.rotation_var_rad2 * std::max(1.0, g.markers / matched);
    m.T_world_body = pose.T_world_body;
    m.rotation_sd_rad = std::sqrt(rot_var);
    // The lever's error is perpendicular to it: two of three components on average.
    m.position_sd_mm = std::sqrt(s2 / matched + rot_var * g.lever_mm * g.lever_mm * (2.0 / 3.0));
  }
  return filter_.update(t_ns, measured_, out);
}

}  // namespace mocap
