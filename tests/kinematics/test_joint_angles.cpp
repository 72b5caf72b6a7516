// Design: the real-time joint-angle solver: exactness on ground truth, accuracy with a
// calibrated model on noisy poses, hinge unwrapping over several turns, validity flags,
// and zero heap allocations per frame.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <numbers>
#include <random>

#include "core/rotation.h"
#include "core/units.h"
#include "kinematics/calibrate.h"
#include "kinematics/joint_angles.h"
#include "tests/kinematics/synthetic_chain.h"
#include "tests/support/alloc_counter.h"

namespace mocap::kinematics {
namespace {

using testing::chain_poses;
using testing::make_chain;
using testing::SyntheticChain;
using testing::SyntheticOptions;

constexpr double kPi = std::numbers::pi;

double wrap(double a) { return std::remainder(a, 2.0 * kPi); }

std::array<BodyPoseView, 3> views(const std::array<Iso3, 3>& T) {
  std::array<BodyPoseView, 3> v;
  for (std::size_t b = 0; b < 3; ++b) v[b] = {true, T[b]};
  return v;
}

TEST(JointAngles, ExactOnGroundTruth) {
  const SyntheticChain c = make_chain({});
  auto solver = JointAngleSolver::create(c.truth, 3);
  ASSERT_TRUE(solver.ok()) << solver.error().message;
  JointAngles out = solver->make_output();
  double offset = 0.0;
  for (std::size_t i = 0; i < c.T_world_body_true.size(); ++i) {
    solver->reset();
    const auto v = views(c.T_world_body_true[i]);
    ASSERT_TRUE(solver->compute(v.data(), out));
    EXPECT_EQ(out.valid_count, 2);
    const JointAngle& s = out.joints[0];
    const Vec3 e = rotation_to_euler_xyz(c.R_shoulder_true[i]);
    EXPECT_EQ(s.type, JointType::kBall);
    EXPECT_NEAR(s.a0, e[0], 1e-9);
    EXPECT_NEAR(s.a1, e[1], 1e-9);
    EXPECT_NEAR(s.a2, e[2], 1e-9);
    EXPECT_GE(s.q_parent_child.w(), 0.0);
    EXPECT_LT((s.q_parent_child.toRotationMatrix() - c.R_shoulder_true[i]).norm(), 1e-9);
    // Hinge: a0 = theta + a constant offset (the zero of frame C), a1 = a2 = 0.
    const JointAngle& h = out.joints[1];
    EXPECT_EQ(h.type, JointType::kHinge);
    if (i == 0) offset = wrap(h.a0 - c.elbow_theta_rad[i]);
    EXPECT_NEAR(wrap(h.a0 - c.elbow_theta_rad[i] - offset), 0.0, 1e-9);
    EXPECT_EQ(h.a1, 0.0);
    EXPECT_EQ(h.a2, 0.0);
  }
}

struct AngleErrors {
  double ball_rms_deg = 0.0;   // over a0, a1, a2
  double hinge_rms_deg = 0.0;  // a0, including the zero offset of the calibrated frame C
};

// Calibrates from `calibration_poses` poses (0.15 mm marker noise), then measures angles
// on 200 fresh poses whose body poses are fitted to markers with 0.05 mm noise on a large
// target (6 markers within 120 mm): pose rotation noise ~0.015 deg per axis. The
// reference is the solver on the noise-free poses with the ground-truth model.
AngleErrors angle_errors(int calibration_poses, bool use_truth_model) {
  SyntheticOptions o;
  o.markers_per_body = 6;
  o.marker_radius_mm = 120.0;
  o.poses = calibration_poses;
  const SyntheticChain cal = make_chain(o);
  auto res = calibrate_joints(cal.targets, cal.topology, cal.input);
  EXPECT_TRUE(res.ok()) << res.error().message;
  if (!res.ok()) return {};
  SyntheticOptions r = o;
  r.poses = 200;
  r.seed = 99;
  const SyntheticChain fresh = make_chain(r);  // motions only; robot and targets of `cal`
  std::mt19937 gen(7);
  std::normal_distribution<double> noise(0.0, 0.05);
  auto est = JointAngleSolver::create(use_truth_model ? cal.truth : res->model, 3);
  auto ref = JointAngleSolver::create(cal.truth, 3);
  EXPECT_TRUE(est.ok() && ref.ok());
  JointAngles a = est->make_output(), b = ref->make_output();
  double ball2 = 0.0, hinge2 = 0.0;
  const std::size_t n = fresh.R_shoulder_true.size();
  for (std::size_t i = 0; i < n; ++i) {
    const auto T = chain_poses(cal.truth, cal.R0_elbow, fresh.T_world_body_true[i][0],
                               fresh.R_shoulder_true[i], fresh.elbow_theta_rad[i]);
    std::array<BodyPoseView, 3> measured;
    for (std::size_t k = 0; k < 3; ++k) {
      const auto& mk = cal.targets.bodies[k].markers_body;
      Eigen::Matrix3Xd src(3, mk.size()), dst(3, mk.size());
      for (std::size_t m = 0; m < mk.size(); ++m) {
        src.col(static_cast<Eigen::Index>(m)) = mk[m];
        dst.col(static_cast<Eigen::Index>(m)) =
            T[k] * mk[m] + Vec3(noise(gen), noise(gen), noise(gen));
      }
      measured[k] = {true, Iso3(Eigen::umeyama(src, dst, false))};
    }
    const auto truth = views(T);
    est->reset();
    ref->reset();
    EXPECT_TRUE(est->compute(measured.data(), a));
    EXPECT_TRUE(ref->compute(truth.data(), b));
    for (double d : {a.joints[0].a0 - b.joints[0].a0, a.joints[0].a1 - b.joints[0].a1,
                     a.joints[0].a2 - b.joints[0].a2}) {
      ball2 += d * d / 3.0;
    }
    const double dh = wrap(a.joints[1].a0 - b.joints[1].a0);
    hinge2 += dh * dh;
  }
  AngleErrors e;
  e.ball_rms_deg = std::sqrt(ball2 / static_cast<double>(n)) * kDegPerRad;
  e.hinge_rms_deg = std::sqrt(hinge2 / static_cast<double>(n)) * kDegPerRad;
  std::printf("calibration poses %d, %s model: angle error rms ball %.4f deg, hinge %.4f deg\n",
              calibration_poses, use_truth_model ? "true" : "calibrated", e.ball_rms_deg,
              e.hinge_rms_deg);
  return e;
}

TEST(JointAngles, PoseNoiseOnlyWithTrueModel) {
  const AngleErrors e = angle_errors(22, true);
  EXPECT_GT(e.ball_rms_deg, 0.0);
  EXPECT_LE(e.ball_rms_deg, 0.05);
  EXPECT_LE(e.hinge_rms_deg, 0.05);
}

TEST(JointAngles, CalibratedModelFrom200Poses) {
  const AngleErrors e = angle_errors(200, false);
  EXPECT_LE(e.ball_rms_deg, 0.05);
  EXPECT_LE(e.hinge_rms_deg, 0.05);
}

TEST(JointAngles, CalibratedModelFrom22Poses) {
  // The hinge zero (frame C: c_y = c x c_z) moves with the calibrated point's error
  // perpendicular to the axis divided by its distance from the body origin.
  const AngleErrors e = angle_errors(22, false);
  EXPECT_LE(e.ball_rms_deg, 0.05);
  EXPECT_LE(e.hinge_rms_deg, 0.1);
}

TEST(JointAngles, HingeUnwrapsOverSeveralTurns) {
  const SyntheticChain c = make_chain({});
  auto solver = JointAngleSolver::create(c.truth, 3);
  ASSERT_TRUE(solver.ok());
  JointAngles out = solver->make_output();
  const Iso3 T_world_torso = c.T_world_body_true[0][0];
  const Mat3 R_s = c.R_shoulder_true[0];
  double first = 0.0;
  int step = 0;
  // Up four turns in 10 deg steps, with a gap of invalid frames, then back down.
  auto drive = [&](double theta) {
    auto v = views(chain_poses(c.truth, c.R0_elbow, T_world_torso, R_s, theta));
    if (step % 50 == 25) v[2].found = false;
    ASSERT_TRUE(solver->compute(v.data(), out));
    if (!v[2].found) {
      EXPECT_FALSE(out.joints[1].valid);
      EXPECT_TRUE(out.joints[0].valid);
    } else {
      if (step == 0) first = out.joints[1].a0;
      EXPECT_NEAR(out.joints[1].a0 - first, theta, 1e-9) << "step " << step;
    }
    ++step;
  };
  for (int k = 0; k <= 144; ++k) drive(k * 10.0 / kDegPerRad);
  for (int k = 144; k >= -72; --k) drive(k * 10.0 / kDegPerRad);
  // After reset the angle starts again in (-pi, pi].
  solver->reset();
  const auto v = views(chain_poses(c.truth, c.R0_elbow, T_world_torso, R_s, 4 * kPi + 0.3));
  ASSERT_TRUE(solver->compute(v.data(), out));
  EXPECT_LE(std::abs(out.joints[1].a0), kPi);
  EXPECT_NEAR(wrap(out.joints[1].a0 - first - 0.3), 0.0, 1e-9);
}

TEST(JointAngles, ZeroAllocationsPerFrame) {
  const SyntheticChain c = make_chain({});
  auto solver = JointAngleSolver::create(c.truth, 3);
  ASSERT_TRUE(solver.ok());
  JointAngles out = solver->make_output();
  std::vector<std::array<BodyPoseView, 3>> frames;
  for (const auto& T : c.T_world_body_true) frames.push_back(views(T));
  frames[3][1].found = false;
  test::AllocationScope scope;
  for (int rep = 0; rep < 100; ++rep) {
    for (const auto& f : frames) (void)solver->compute(f.data(), out);
  }
  EXPECT_EQ(scope.count(), 0u);
}

TEST(JointAngles, CreateAndComputeErrors) {
  SyntheticChain c = make_chain({});
  JointModel m = c.truth;
  m.joints[1].calibrated = false;
  auto s1 = JointAngleSolver::create(m, 3);
  ASSERT_FALSE(s1.ok());
  EXPECT_EQ(s1.error().message, "model.yaml: joints.elbow: joint is not calibrated");
  auto s2 = JointAngleSolver::create(c.truth, 2);
  ASSERT_FALSE(s2.ok());
  EXPECT_EQ(s2.error().message, "model.yaml: joints.elbow: invalid parent/child body index");
  auto s3 = JointAngleSolver::create(c.truth, 3);
  ASSERT_TRUE(s3.ok());
  JointAngles wrong;  // not sized by make_output
  const auto v = views(c.T_world_body_true[0]);
  EXPECT_FALSE(s3->compute(v.data(), wrong));
}

}  // namespace
}  // namespace mocap::kinematics
