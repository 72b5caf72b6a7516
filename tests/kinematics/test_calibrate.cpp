// Design: the whole calibration (linear estimates + Ceres refinement + covariance) on a
// synthetic torso -> upper_arm (ball) -> lower_arm (hinge) chain: accuracy against ground
// truth, reported residuals/uncertainties, degenerate recordings and input validation.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "core/units.h"
#include "kinematics/calibrate.h"
#include "tests/kinematics/synthetic_chain.h"

namespace mocap::kinematics {
namespace {

using testing::angle_deg;
using testing::make_chain;
using testing::ShoulderMotion;
using testing::SyntheticChain;
using testing::SyntheticOptions;

const std::vector<double>* extra(const JointSpec& s, const std::string& key) {
  for (const auto& [k, v] : s.extra) {
    if (k == key) return &v;
  }
  return nullptr;
}

// Distance of point p from the line through c with direction a.
double line_distance(const Vec3& p, const Vec3& c, const Vec3& a) {
  return (p - c).cross(a.normalized()).norm();
}

class CalibrateSeeds : public ::testing::TestWithParam<unsigned> {};

TEST_P(CalibrateSeeds, RefinedModelMeetsAccuracyTargets) {
  SyntheticOptions o;
  o.seed = GetParam();
  o.marker_noise_mm = 0.15;
  const SyntheticChain c = make_chain(o);
  auto res = calibrate_joints(c.targets, c.topology, c.input);
  ASSERT_TRUE(res.ok()) << res.error().message;
  const JointSpec& s = res->model.joints[0];
  const JointSpec& e = res->model.joints[1];
  const JointSpec& ts = c.truth.joints[0];
  const JointSpec& te = c.truth.joints[1];
  ASSERT_TRUE(s.calibrated && e.calibrated);
  // Ball centre in both frames.
  EXPECT_LE((s.center_parent - ts.center_parent).norm(), 0.3);
  EXPECT_LE((s.center_child - ts.center_child).norm(), 0.3);
  // Hinge axis direction and position (line distance and the canonical point).
  EXPECT_LE(angle_deg(e.axis_parent, te.axis_parent), 0.1);
  EXPECT_LE(angle_deg(e.axis_child, te.axis_child), 0.1);
  EXPECT_LE(line_distance(e.center_parent, te.center_parent, te.axis_parent), 0.3);
  EXPECT_LE(line_distance(e.center_child, te.center_child, te.axis_child), 0.3);
  EXPECT_LE((e.center_parent - te.center_parent).norm(), 0.3);
  EXPECT_LE((e.center_child - te.center_child).norm(), 0.3);
  // Residuals: marker noise 0.15 mm per coordinate -> 3D RMS ~0.26 mm minus fitted dof.
  ASSERT_EQ(res->report.bodies.size(), 3u);
  for (const auto& b : res->report.bodies) {
    EXPECT_GT(b.rms_mm, 0.1) << b.body;
    EXPECT_LT(b.rms_mm, 0.35) << b.body;
    EXPECT_EQ(b.observations, 22 * 5);
  }
  EXPECT_EQ(res->report.refine_frames, 22);
  EXPECT_TRUE(res->report.warnings.empty()) << res->report.warnings.front();
  // Extras: residuals and uncertainties of plausible size.
  ASSERT_NE(extra(s, "residual_rms_mm"), nullptr);
  const auto* sp = extra(s, "center_parent_std_mm");
  const auto* sc = extra(s, "center_child_std_mm");
  ASSERT_TRUE(sp && sc);
  ASSERT_EQ(sp->size(), 3u);
  for (double v : *sp) EXPECT_TRUE(v > 0.003 && v < 0.3) << v;
  const auto* ap = extra(e, "axis_parent_std_deg");
  const auto* pos = extra(e, "axis_position_std_mm");
  ASSERT_TRUE(ap && pos && extra(e, "axis_child_std_deg"));
  EXPECT_TRUE((*ap)[0] > 1e-4 && (*ap)[0] < 0.1) << (*ap)[0];
  EXPECT_TRUE((*pos)[0] > 1e-3 && (*pos)[0] < 0.3) << (*pos)[0];
  ASSERT_NE(extra(e, "linear_singular_values"), nullptr);
  EXPECT_EQ(extra(e, "linear_singular_values")->size(), 6u);
}

INSTANTIATE_TEST_SUITE_P(Seeds, CalibrateSeeds, ::testing::Values(1u, 2u, 3u));

TEST(Calibrate, UncertaintyIsConsistentWithErrors) {
  // Over several seeds the ball-centre error should be of the order of the reported std.
  double err2 = 0.0, var = 0.0;
  for (unsigned seed = 10; seed < 16; ++seed) {
    SyntheticOptions o;
    o.seed = seed;
    const SyntheticChain c = make_chain(o);
    auto res = calibrate_joints(c.targets, c.topology, c.input);
    ASSERT_TRUE(res.ok()) << res.error().message;
    const Vec3 d = res->model.joints[0].center_parent - c.truth.joints[0].center_parent;
    err2 += d.squaredNorm();
    for (double s : *extra(res->model.joints[0], "center_parent_std_mm")) var += s * s;
  }
  const double ratio = std::sqrt(err2 / var);
  EXPECT_GT(ratio, 0.4);
  EXPECT_LT(ratio, 2.5);
}

TEST(Calibrate, FormatReportListsJointsBodiesAndExtras) {
  const SyntheticChain c = make_chain({});
  auto res = calibrate_joints(c.targets, c.topology, c.input);
  ASSERT_TRUE(res.ok()) << res.error().message;
  const std::string text = format_report(*res);
  for (const char* part : {"joint shoulder (ball, torso -> upper_arm)", "joint elbow (hinge",
                           "axis_position_std_mm:", "body lower_arm: residual rms",
                           "refinement: 22 frames", "linear: 22 poses"}) {
    EXPECT_NE(text.find(part), std::string::npos) << part << "\n" << text;
  }
}

TEST(Calibrate, LinearOnlyWhenRefinementDisabled) {
  const SyntheticChain c = make_chain({});
  CalibrationOptions opt;
  opt.refine = false;
  auto res = calibrate_joints(c.targets, c.topology, c.input, opt);
  ASSERT_TRUE(res.ok()) << res.error().message;
  EXPECT_EQ(res->report.refine_frames, 0);
  EXPECT_EQ(extra(res->model.joints[0], "residual_rms_mm"), nullptr);
  EXPECT_LT((res->model.joints[0].center_parent - c.truth.joints[0].center_parent).norm(), 1.0);
}

TEST(Calibrate, SurvivesOcclusionAndOutliers) {
  SyntheticOptions o;
  o.poses = 40;
  SyntheticChain c = make_chain(o);
  for (std::size_t f = 0; f < c.input.frames.size(); f += 5) {
    c.input.frames[f].bodies[2].found = false;  // lower arm occluded
    c.input.frames[f].bodies[2].markers.clear();
  }
  c.input.frames[3].bodies[1].markers[0].X_world_mm += Vec3(15, -10, 5);  // stray match
  auto res = calibrate_joints(c.targets, c.topology, c.input);
  ASSERT_TRUE(res.ok()) << res.error().message;
  EXPECT_LE((res->model.joints[0].center_child - c.truth.joints[0].center_child).norm(), 0.3);
  EXPECT_EQ(res->report.joints[1].frames_used, 32);
}

TEST(Calibrate, DegenerateRecordingsGiveErrorsWithNumbers) {
  {
    SyntheticOptions o;
    o.poses = 3;
    const SyntheticChain c = make_chain(o);
    auto res = calibrate_joints(c.targets, c.topology, c.input);
    ASSERT_FALSE(res.ok());
    EXPECT_EQ(res.error().message,
              "calibration: joint 'shoulder' (ball): 3 poses, at least 6 distinct poses needed");
  }
  {
    SyntheticOptions o;
    o.shoulder_range_deg = 2.0;
    const SyntheticChain c = make_chain(o);
    auto res = calibrate_joints(c.targets, c.topology, c.input);
    ASSERT_FALSE(res.ok());
    EXPECT_NE(res.error().message.find("joint 'shoulder' (ball): range of motion too small"),
              std::string::npos)
        << res.error().message;
  }
  {  // elbow declared a ball joint
    SyntheticChain c = make_chain({});
    c.topology.joints[1].type = JointType::kBall;
    auto res = calibrate_joints(c.targets, c.topology, c.input);
    ASSERT_FALSE(res.ok());
    EXPECT_NE(res.error().message.find("joint 'elbow' (ball): moved about one axis only"),
              std::string::npos)
        << res.error().message;
  }
  {  // shoulder with planar motion declared a hinge
    SyntheticOptions o;
    o.shoulder_motion = ShoulderMotion::kPlanar;
    SyntheticChain c = make_chain(o);
    c.topology.joints[0].type = JointType::kHinge;
    auto res = calibrate_joints(c.targets, c.topology, c.input);
    ASSERT_FALSE(res.ok());
    EXPECT_NE(res.error().message.find("joint 'shoulder' (hinge): not a hinge motion"),
              std::string::npos)
        << res.error().message;
  }
}

TEST(Calibrate, InputValidation) {
  SyntheticChain c = make_chain({});
  {
    CalibrationInput in = c.input;
    in.frames[4].bodies.pop_back();
    auto res = calibrate_joints(c.targets, c.topology, in);
    ASSERT_FALSE(res.ok());
    EXPECT_EQ(res.error().message, "calibration input: frames[4]: 2 bodies, targets have 3");
  }
  {
    CalibrationInput in = c.input;
    in.frames[2].bodies[1].markers[3].marker_index = 9;
    auto res = calibrate_joints(c.targets, c.topology, in);
    ASSERT_FALSE(res.ok());
    EXPECT_EQ(res.error().message,
              "calibration input: frames[2].bodies[1] ('upper_arm').markers[3]: marker index 9 "
              "out of range (target has 5)");
  }
  {
    JointModel topo = c.topology;
    topo.joints[1].child_index = 1;
    topo.joints[1].child = "upper_arm";
    auto res = calibrate_joints(c.targets, topo, c.input);
    ASSERT_FALSE(res.ok());
    EXPECT_EQ(res.error().message, "joints.yaml: joints.elbow: parent and child are the same body");
  }
  {
    JointModel topo = c.topology;
    topo.joints[1].parent_index = 0;
    topo.joints[1].child_index = 1;
    auto res = calibrate_joints(c.targets, topo, c.input);
    ASSERT_FALSE(res.ok());
    EXPECT_NE(res.error().message.find("is already the child of joint 'shoulder'"),
              std::string::npos);
  }
}

}  // namespace
}  // namespace mocap::kinematics
