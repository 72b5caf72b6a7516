// Design: the linear estimators (Eq. 2 ball, SCoRE form, rank-5 hinge), frame C and the
// degeneracy checks, on synthetic chains with known ground truth.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "core/units.h"
#include "kinematics/joint_frame.h"
#include "kinematics/linear_estimation.h"
#include "tests/kinematics/synthetic_chain.h"

namespace mocap::kinematics {
namespace {

using testing::angle_deg;
using testing::make_chain;
using testing::ShoulderMotion;
using testing::SyntheticChain;
using testing::SyntheticOptions;

std::vector<RelativePose> relative(const SyntheticChain& c, int parent, int child, bool truth) {
  std::vector<RelativePose> out;
  for (std::size_t i = 0; i < c.input.frames.size(); ++i) {
    const Iso3& Tp = truth
                         ? c.T_world_body_true[i][static_cast<std::size_t>(parent)]
                         : c.input.frames[i].bodies[static_cast<std::size_t>(parent)].T_world_body;
    const Iso3& Tc = truth ? c.T_world_body_true[i][static_cast<std::size_t>(child)]
                           : c.input.frames[i].bodies[static_cast<std::size_t>(child)].T_world_body;
    out.push_back(relative_pose(Tp, Tc));
  }
  return out;
}

TEST(LinearBall, ExactOnNoiseFreePoses) {
  const SyntheticChain c = make_chain({});
  auto est = estimate_ball(relative(c, 0, 1, true), {}, "test");
  ASSERT_TRUE(est.ok()) << est.error().message;
  EXPECT_LT((est->center_parent - c.truth.joints[0].center_parent).norm(), 1e-8);
  EXPECT_LT((est->center_child - c.truth.joints[0].center_child).norm(), 1e-8);
  EXPECT_LT(est->diagnostics.residual_rms_mm, 1e-8);
  EXPECT_EQ(est->diagnostics.poses, 22);
}

TEST(LinearBall, NoisyPosesWithinHalfMillimetre) {
  const SyntheticChain c = make_chain({});
  auto est = estimate_ball(relative(c, 0, 1, false), {}, "test");
  ASSERT_TRUE(est.ok()) << est.error().message;
  EXPECT_LT((est->center_parent - c.truth.joints[0].center_parent).norm(), 0.5);
  EXPECT_LT((est->center_child - c.truth.joints[0].center_child).norm(), 0.5);
  EXPECT_GT(est->diagnostics.residual_rms_mm, 0.0);
}

TEST(LinearBall, ScoreWorldFormMatchesEquation2) {
  const SyntheticChain c = make_chain({});
  std::vector<Iso3> Tp, Tc;
  for (const auto& f : c.input.frames) {
    Tp.push_back(f.bodies[0].T_world_body);
    Tc.push_back(f.bodies[1].T_world_body);
  }
  auto rel = estimate_ball(relative(c, 0, 1, false), {}, "test");
  auto world = estimate_ball_world(Tp, Tc, {}, "test");
  ASSERT_TRUE(rel.ok() && world.ok());
  EXPECT_LT((rel->center_parent - world->center_parent).norm(), 1e-6);
  EXPECT_LT((rel->center_child - world->center_child).norm(), 1e-6);
  for (std::size_t k = 0; k < 6; ++k) {
    EXPECT_NEAR(rel->diagnostics.singular_values[k], world->diagnostics.singular_values[k], 1e-9);
  }
}

TEST(LinearHinge, ExactAxisAndMinimumNormPointOnNoiseFreePoses) {
  const SyntheticChain c = make_chain({});
  const JointSpec& e = c.truth.joints[1];
  auto est = estimate_hinge(relative(c, 1, 2, true), {}, "test");
  ASSERT_TRUE(est.ok()) << est.error().message;
  EXPECT_LT(angle_deg(est->axis_parent, e.axis_parent), 1e-6);
  EXPECT_LT(angle_deg(est->axis_child, e.axis_child), 1e-6);
  EXPECT_LT((est->center_parent - e.center_parent).norm(), 1e-6);
  EXPECT_LT((est->center_child - e.center_child).norm(), 1e-6);
  // The minimum-norm point: c_p . a_p + c_c . a_c = 0.
  EXPECT_NEAR(est->center_parent.dot(est->axis_parent) + est->center_child.dot(est->axis_child),
              0.0, 1e-6);
}

TEST(LinearHinge, SignHintFlipsBothAxes) {
  const SyntheticChain c = make_chain({});
  const Vec3 hint = -c.truth.joints[1].axis_parent;
  auto est = estimate_hinge(relative(c, 1, 2, true), {}, "test", hint);
  ASSERT_TRUE(est.ok());
  EXPECT_LT(angle_deg(est->axis_parent, -c.truth.joints[1].axis_parent), 1e-6);
  EXPECT_LT(angle_deg(est->axis_child, -c.truth.joints[1].axis_child), 1e-6);
}

TEST(Degeneracy, TooFewPoses) {
  SyntheticOptions o;
  o.poses = 3;
  const SyntheticChain c = make_chain(o);
  auto ball = estimate_ball(relative(c, 0, 1, false), {}, "joint 'shoulder' (ball)");
  ASSERT_FALSE(ball.ok());
  EXPECT_NE(ball.error().message.find("3 poses, at least 6"), std::string::npos)
      << ball.error().message;
  auto hinge = estimate_hinge(relative(c, 1, 2, false), {}, "joint 'elbow' (hinge)");
  ASSERT_FALSE(hinge.ok());
  EXPECT_NE(hinge.error().message.find("3 poses"), std::string::npos);
}

TEST(Degeneracy, SmallRangeOfMotion) {
  SyntheticOptions o;
  o.shoulder_range_deg = 2.0;
  o.elbow_min_deg = 40.0;
  o.elbow_max_deg = 42.0;
  const SyntheticChain c = make_chain(o);
  auto ball = estimate_ball(relative(c, 0, 1, false), {}, "shoulder");
  ASSERT_FALSE(ball.ok());
  EXPECT_NE(ball.error().message.find("range of motion too small"), std::string::npos)
      << ball.error().message;
  EXPECT_NE(ball.error().message.find("singular values ["), std::string::npos);
  auto hinge = estimate_hinge(relative(c, 1, 2, false), {}, "elbow");
  ASSERT_FALSE(hinge.ok());
  EXPECT_NE(hinge.error().message.find("range of motion about the axis too small: s5 = "),
            std::string::npos)
      << hinge.error().message;
}

TEST(Degeneracy, HingeMotionGivenToBallEstimator) {
  const SyntheticChain c = make_chain({});
  auto ball = estimate_ball(relative(c, 1, 2, false), {}, "elbow as ball");
  ASSERT_FALSE(ball.ok());
  EXPECT_NE(ball.error().message.find("moved about one axis only"), std::string::npos)
      << ball.error().message;
  EXPECT_NE(ball.error().message.find("s6 = "), std::string::npos);
}

TEST(Degeneracy, BallOneAxisMotionIsRejectedByBallEstimator) {
  SyntheticOptions o;
  o.shoulder_motion = ShoulderMotion::kOneAxis;
  const SyntheticChain c = make_chain(o);
  auto ball = estimate_ball(relative(c, 0, 1, false), {}, "shoulder");
  ASSERT_FALSE(ball.ok());
  EXPECT_NE(ball.error().message.find("one axis only"), std::string::npos);
}

TEST(Degeneracy, PlanarBallMotionGivenToHingeEstimator) {
  SyntheticOptions o;
  o.shoulder_motion = ShoulderMotion::kPlanar;
  const SyntheticChain c = make_chain(o);
  auto hinge = estimate_hinge(relative(c, 0, 1, false), {}, "shoulder as hinge");
  ASSERT_FALSE(hinge.ok());
  EXPECT_NE(hinge.error().message.find("not a hinge motion: s6/s5 = "), std::string::npos)
      << hinge.error().message;
  // The same planar (two-axis) motion is a valid ball-joint recording.
  auto ball = estimate_ball(relative(c, 0, 1, false), {}, "shoulder");
  EXPECT_TRUE(ball.ok()) << ball.error().message;
}

TEST(Degeneracy, SingularValuesMatchSmallAngleAnalysis) {
  // Hinge rotating uniformly over 120 deg: variance v = (120 deg)^2 / 12 about the axis;
  // s4 = s5 ~ sqrt(v / 2) (small-angle analysis, slightly smaller for large angles).
  SyntheticOptions o;
  o.poses = 400;
  o.marker_noise_mm = 0.0;
  const SyntheticChain c = make_chain(o);
  auto hinge = estimate_hinge(relative(c, 1, 2, true), {}, "elbow");
  ASSERT_TRUE(hinge.ok());
  const double expected_deg = std::sqrt(120.0 * 120.0 / 12.0 / 2.0);
  EXPECT_NEAR(hinge->diagnostics.singular_value_deg(4), expected_deg, 0.15 * expected_deg);
  EXPECT_LT(hinge->diagnostics.singular_value_deg(5), 1e-6);
}

TEST(HingeFrame, RightHandedWithPaperAxes) {
  const Vec3 c(10, 20, 30), a = Vec3(1, -2, 0.5).normalized();
  const HingeFrame f = make_hinge_frame(c, a);
  const Mat3 R = f.T_body_joint.linear();
  EXPECT_FALSE(f.degenerate);
  EXPECT_NEAR(R.determinant(), 1.0, 1e-12);
  EXPECT_LT((R.col(2) - a).norm(), 1e-12);
  EXPECT_LT((R.col(1) - c.cross(a).normalized()).norm(), 1e-12);
  EXPECT_LT((R.col(0) - R.col(1).cross(a)).norm(), 1e-12);
  EXPECT_LT((f.T_body_joint.translation() - c).norm(), 1e-12);
}

TEST(HingeFrame, PointOnAxisThroughOriginUsesFallback) {
  const Vec3 a = Vec3(0.2, 0.1, 1.0).normalized();
  for (const Vec3& c : {Vec3(a * 50.0), Vec3::Zero().eval()}) {
    const HingeFrame f = make_hinge_frame(c, a);
    EXPECT_TRUE(f.degenerate);
    const Mat3 R = f.T_body_joint.linear();
    EXPECT_NEAR(R.determinant(), 1.0, 1e-12);
    EXPECT_LT((R.transpose() * R - Mat3::Identity()).norm(), 1e-12);
    EXPECT_LT((R.col(2) - a).norm(), 1e-12);
  }
}

}  // namespace
}  // namespace mocap::kinematics
