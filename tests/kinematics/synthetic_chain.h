// Design: synthetic ground truth for the kinematics tests and benchmarks: a random chain
// torso -(ball "shoulder")-> upper_arm -(hinge "elbow")-> lower_arm with random joint
// parameters, random marker targets whose body origins are away from the markers, random
// poses, Gaussian marker noise, and body poses fitted to the noisy markers (Umeyama), as
// the tracker would deliver them. Motion modes produce the degenerate recordings.
#pragma once

#include <array>
#include <vector>

#include "core/types.h"
#include "formats/joints_yaml.h"
#include "formats/targets_yaml.h"
#include "kinematics/calibrate.h"

namespace mocap::kinematics::testing {

enum class ShoulderMotion {
  kFull,     // Euler angles uniform in +-range/2 about all three axes
  kOneAxis,  // rotation about one fixed axis only (hinge-like)
  kPlanar,   // rotation vectors in a plane: two axes, no twist
};

struct SyntheticOptions {
  int poses = 22;
  unsigned seed = 1;
  int markers_per_body = 5;
  double marker_radius_mm = 80.0;  // markers uniform in a ball of this radius
  double marker_noise_mm = 0.15;   // Gaussian, per coordinate
  ShoulderMotion shoulder_motion = ShoulderMotion::kFull;
  double shoulder_range_deg = 90.0;  // full width per axis
  double elbow_min_deg = 0.0, elbow_max_deg = 120.0;
};

struct SyntheticChain {
  TargetSet targets;    // torso, upper_arm, lower_arm
  JointModel truth;     // calibrated ground truth (hinge point at the minimum-norm position)
  JointModel topology;  // the same joints, uncalibrated
  Mat3 R0_elbow = Mat3::Identity();  // hinge: R_rel(theta) = AngleAxis(theta, a_p) * R0
  std::vector<std::array<Iso3, 3>> T_world_body_true;
  std::vector<Mat3> R_shoulder_true;  // R_parent^T R_child
  std::vector<double> elbow_theta_rad;
  CalibrationInput input;  // noisy markers and fitted poses, all bodies found
};

SyntheticChain make_chain(const SyntheticOptions& options);

// T_world_body of the chain for a shoulder rotation and an elbow angle.
std::array<Iso3, 3> chain_poses(const JointModel& truth, const Mat3& R0_elbow,
                                const Iso3& T_world_torso, const Mat3& R_shoulder,
                                double elbow_theta_rad);

// Angle between two directions, degrees.
double angle_deg(const Vec3& a, const Vec3& b);

}  // namespace mocap::kinematics::testing
