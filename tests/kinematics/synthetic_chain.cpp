// Design: see synthetic_chain.h. Deterministic for a given seed (std::mt19937).
#include "tests/kinematics/synthetic_chain.h"

#include <Eigen/Geometry>
#include <cmath>
#include <numbers>
#include <random>

#include "core/rotation.h"
#include "core/units.h"

namespace mocap::kinematics::testing {
namespace {

struct Rng {
  std::mt19937 gen;
  double uniform(double a, double b) { return std::uniform_real_distribution<double>(a, b)(gen); }
  double normal(double s) { return std::normal_distribution<double>(0.0, s)(gen); }
  Vec3 box(double h) { return Vec3(uniform(-h, h), uniform(-h, h), uniform(-h, h)); }
  Vec3 unit() {
    Vec3 v;
    do v = box(1.0);
    while (v.norm() > 1.0 || v.norm() < 0.1);
    return v.normalized();
  }
  Mat3 rotation() {
    return Eigen::AngleAxisd(uniform(-std::numbers::pi, std::numbers::pi), unit())
        .toRotationMatrix();
  }
};

JointSpec joint(const char* name, JointType type, const char* parent, const char* child, int pi,
                int ci) {
  JointSpec s;
  s.name = name;
  s.type = type;
  s.parent = parent;
  s.child = child;
  s.parent_index = pi;
  s.child_index = ci;
  return s;
}

}  // namespace

std::array<Iso3, 3> chain_poses(const JointModel& truth, const Mat3& R0_elbow,
                                const Iso3& T_world_torso, const Mat3& R_shoulder,
                                double elbow_theta_rad) {
  const JointSpec& s = truth.joints[0];
  const JointSpec& e = truth.joints[1];
  // X_parent = c_p + R (X_child - c_c)  <=>  T_parent_child = [R, c_p - R c_c].
  const Iso3 T_torso_upper = make_iso(R_shoulder, s.center_parent - R_shoulder * s.center_child);
  const Mat3 R_e = Eigen::AngleAxisd(elbow_theta_rad, e.axis_parent).toRotationMatrix() * R0_elbow;
  const Iso3 T_upper_lower = make_iso(R_e, e.center_parent - R_e * e.center_child);
  const Iso3 T_world_upper = T_world_torso * T_torso_upper;
  return {T_world_torso, T_world_upper, T_world_upper * T_upper_lower};
}

SyntheticChain make_chain(const SyntheticOptions& o) {
  Rng rng{std::mt19937(o.seed)};
  SyntheticChain c;
  const char* names[3] = {"torso", "upper_arm", "lower_arm"};
  for (const char* n : names) {
    MarkerTarget t;
    t.name = n;
    const Vec3 centre = rng.box(60.0);  // body origin away from the markers
    while (static_cast<int>(t.markers_body.size()) < o.markers_per_body) {
      const Vec3 m = centre + rng.unit() * o.marker_radius_mm * std::cbrt(rng.uniform(0.2, 1.0));
      bool ok = true;
      for (const Vec3& other : t.markers_body) ok = ok && (other - m).norm() > 25.0;
      if (ok) t.markers_body.push_back(m);
    }
    c.targets.bodies.push_back(t);
  }
  c.topology.joints = {joint("shoulder", JointType::kBall, "torso", "upper_arm", 0, 1),
                       joint("elbow", JointType::kHinge, "upper_arm", "lower_arm", 1, 2)};
  c.truth = c.topology;
  JointSpec& s = c.truth.joints[0];
  s.center_parent = Vec3(150, 50, 250) + rng.box(50.0);
  s.center_child = Vec3(0, 0, 160) + rng.box(40.0);
  JointSpec& e = c.truth.joints[1];
  e.axis_parent = rng.unit();
  if (e.axis_parent.z() < 0) e.axis_parent = -e.axis_parent;  // the calibrator's sign hint
  c.R0_elbow = rng.rotation();
  e.axis_child = c.R0_elbow.transpose() * e.axis_parent;
  e.center_parent = Vec3(0, 0, -150) + rng.box(40.0);
  e.center_child = Vec3(0, 0, 130) + rng.box(40.0);
  // Move the hinge point to the minimum-norm position (the estimators' convention).
  const double slide =
      -(e.center_parent.dot(e.axis_parent) + e.center_child.dot(e.axis_child)) / 2.0;
  e.center_parent += slide * e.axis_parent;
  e.center_child += slide * e.axis_child;
  s.calibrated = e.calibrated = true;

  const Vec3 one_axis = rng.unit();
  Mat3 plane_basis = rng.rotation();
  const double half = o.shoulder_range_deg * kRadPerDeg / 2.0;
  for (int i = 0; i < o.poses; ++i) {
    const Iso3 T_world_torso = make_iso(rng.rotation(), Vec3(0, 0, 2500) + rng.box(300.0));
    Mat3 R_s;
    switch (o.shoulder_motion) {
      case ShoulderMotion::kFull:
        R_s = euler_xyz_to_rotation(
            Vec3(rng.uniform(-half, half), rng.uniform(-half, half), rng.uniform(-half, half)));
        break;
      case ShoulderMotion::kOneAxis:
        R_s = Eigen::AngleAxisd(rng.uniform(-half, half), one_axis).toRotationMatrix();
        break;
      case ShoulderMotion::kPlanar: {
        const Vec3 w = plane_basis.col(0) * rng.uniform(-half, half) +
                       plane_basis.col(1) * rng.uniform(-half, half);
        R_s = Eigen::AngleAxisd(w.norm(), w.normalized()).toRotationMatrix();
        break;
      }
    }
    const double theta = rng.uniform(o.elbow_min_deg, o.elbow_max_deg) * kRadPerDeg;
    const auto T = chain_poses(c.truth, c.R0_elbow, T_world_torso, R_s, theta);
    c.T_world_body_true.push_back(T);
    c.R_shoulder_true.push_back(R_s);
    c.elbow_theta_rad.push_back(theta);

    CalibrationFrame frame;
    for (std::size_t b = 0; b < 3; ++b) {
      BodyObservation obs;
      const auto& markers = c.targets.bodies[b].markers_body;
      Eigen::Matrix3Xd src(3, markers.size()), dst(3, markers.size());
      for (std::size_t m = 0; m < markers.size(); ++m) {
        const Vec3 X =
            T[b] * markers[m] + Vec3(rng.normal(o.marker_noise_mm), rng.normal(o.marker_noise_mm),
                                     rng.normal(o.marker_noise_mm));
        obs.markers.push_back({static_cast<int>(m), X});
        src.col(static_cast<Eigen::Index>(m)) = markers[m];
        dst.col(static_cast<Eigen::Index>(m)) = X;
      }
      obs.found = true;
      obs.T_world_body = Iso3(Eigen::umeyama(src, dst, false));
      frame.bodies.push_back(obs);
    }
    c.input.frames.push_back(frame);
  }
  return c;
}

double angle_deg(const Vec3& a, const Vec3& b) {
  return std::atan2(a.cross(b).norm(), a.dot(b)) * kDegPerRad;
}

}  // namespace mocap::kinematics::testing
