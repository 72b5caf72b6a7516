// Tests of src/track/evaluation.h on small hand-made inputs with known answers:
// calibration errors of a model with a known offset/tilt, Table 1A distances of poses
// with known hold positions, Table 1B deviations of alternating poses and angles, and
// angle errors with a known bias and geodesic error.
#include <gtest/gtest.h>

#include <cmath>

#include "core/rotation.h"
#include "core/units.h"
#include "tests/support/test_support.h"
#include "track/evaluation.h"

namespace mocap {
namespace {

JointModel two_joint_model() {
  JointModel m;
  JointSpec ball;
  ball.name = "shoulder";
  ball.type = JointType::kBall;
  ball.parent = "torso";
  ball.child = "upper_arm";
  ball.calibrated = true;
  ball.center_parent = Vec3(10, 20, 30);
  ball.center_child = Vec3(0, 0, 100);
  JointSpec hinge;
  hinge.name = "elbow";
  hinge.type = JointType::kHinge;
  hinge.parent = "upper_arm";
  hinge.child = "lower_arm";
  hinge.calibrated = true;
  hinge.center_parent = Vec3(0, 0, -100);
  hinge.center_child = Vec3(0, 0, 90);
  hinge.axis_parent = Vec3::UnitX();
  hinge.axis_child = Vec3::UnitY();
  m.joints = {ball, hinge};
  return m;
}

TEST(CalibrationErrors, KnownOffsetsAndTilt) {
  const JointModel truth = two_joint_model();
  JointModel est = truth;
  est.joints[0].center_parent += Vec3(0.3, 0.4, 0.0);  // 0.5 mm
  est.joints[0].center_child += Vec3(0.0, 0.0, -1.2);  // 1.2 mm
  // Hinge: centre slid 2 mm along the axis (no position error) and moved 0.25 mm off it;
  // axis tilted by 0.1 deg and flipped (direction sign is free).
  est.joints[1].center_parent += Vec3(2.0, 0.25, 0.0);
  est.joints[1].axis_parent = -(rot_z(0.1 * kRadPerDeg) * Vec3::UnitX());
  est.joints[1].axis_child = rot_x(0.2 * kRadPerDeg) * Vec3::UnitY();
  auto r = calibration_errors(est, truth);
  ASSERT_TRUE(r) << r.error().message;
  ASSERT_EQ(r->size(), 2u);
  EXPECT_NEAR((*r)[0].center_parent_mm, 0.5, 1e-12);
  EXPECT_NEAR((*r)[0].center_child_mm, 1.2, 1e-12);
  EXPECT_EQ((*r)[0].type, JointType::kBall);
  EXPECT_NEAR((*r)[1].center_parent_mm, std::hypot(2.0, 0.25), 1e-12);
  EXPECT_NEAR((*r)[1].axis_parent_deg, 0.1, 1e-9);
  EXPECT_NEAR((*r)[1].axis_child_deg, 0.2, 1e-9);
  // Distance of the true centre from the estimated line (tilted by 0.1 deg, through a
  // point 2 mm along and 0.25 mm across): 0.25 cos(0.1 deg) - 2 sin(0.1 deg).
  EXPECT_NEAR((*r)[1].axis_position_parent_mm,
              0.25 * std::cos(0.1 * kRadPerDeg) - 2.0 * std::sin(0.1 * kRadPerDeg), 1e-12);
  EXPECT_NEAR((*r)[1].axis_position_child_mm, 0.0, 1e-12);
}

TEST(CalibrationErrors, RejectsMissingOrMismatchedJoints) {
  const JointModel truth = two_joint_model();
  JointModel est = truth;
  est.joints.pop_back();
  EXPECT_FALSE(calibration_errors(est, truth));
  est = truth;
  est.joints[1].type = JointType::kBall;
  EXPECT_FALSE(calibration_errors(est, truth));
}

PoseRow pose(std::int64_t frame, const std::string& body, const Vec3& t,
             const Quat& q = Quat::Identity()) {
  PoseRow p;
  p.frame = frame;
  p.body = body;
  p.t_world_body = t;
  p.q_world_body = q;
  return p;
}

TEST(DistanceErrors, KnownHoldPositions) {
  const std::vector<Segment> segs = {
      {0, true, 0, 1, Vec3(0, -150, 0)}, {1, false, 2, 2, Vec3::Zero()},
      {2, true, 3, 4, Vec3(0, 250, 0)},  {3, true, 5, 6, Vec3(-150, 0, 0)},
      {4, false, 7, 7, Vec3::Zero()},    {5, true, 8, 9, Vec3(250, 0, 0)}};
  std::vector<PoseRow> poses;
  // Body "a": first move measured 401 mm (hold means -150 and 251, with +-0.5 jitter),
  // second 399 mm. Body "b": exact, but absent in hold 5.
  poses.push_back(pose(0, "a", Vec3(0, -150.5, 0)));
  poses.push_back(pose(1, "a", Vec3(0, -149.5, 0)));
  poses.push_back(pose(2, "a", Vec3(0, 77, 0)));  // moving: ignored
  poses.push_back(pose(3, "a", Vec3(0, 251, 0)));
  poses.push_back(pose(4, "a", Vec3(0, 251, 0)));
  poses.push_back(pose(5, "a", Vec3(-150, 10, 5)));
  poses.push_back(pose(8, "a", Vec3(249, 10, 5)));
  poses.push_back(pose(0, "b", Vec3(1, -150, 0)));
  poses.push_back(pose(3, "b", Vec3(1, 250, 0)));
  poses.push_back(pose(5, "b", Vec3(-150, 0, 0)));
  const auto r = distance_errors(poses, segs);
  ASSERT_EQ(r.size(), 2u);
  EXPECT_EQ(r[0].body, "a");
  ASSERT_EQ(r[0].pairs.size(), 2u);  // holds 2 -> 3 are not separated by a move
  EXPECT_EQ(r[0].pairs_used, 2);
  EXPECT_NEAR(r[0].pairs[0].true_mm, 400.0, 1e-12);
  EXPECT_NEAR(r[0].pairs[0].measured_mm, 401.0, 1e-12);
  EXPECT_NEAR(r[0].pairs[1].measured_mm, 399.0, 1e-12);
  EXPECT_NEAR(r[0].rmse_mm, 1.0, 1e-12);
  EXPECT_NEAR(r[0].mean_error_mm, 0.0, 1e-12);
  EXPECT_NEAR(r[0].max_abs_error_mm, 1.0, 1e-12);
  EXPECT_EQ(r[1].pairs_used, 1);
  EXPECT_TRUE(std::isnan(r[1].pairs[1].measured_mm));
  EXPECT_NEAR(r[1].rmse_mm, 0.0, 1e-12);
}

TEST(JointPrecision, AlternatingPosesGiveKnownDeviations) {
  JointModel model = two_joint_model();
  std::vector<PoseRow> poses;
  std::vector<AngleRow> angles;
  // The parent is rotated arbitrarily per frame (the precision is frame-free); the child
  // alternates +-0.5 mm along the parent's x and +-0.2 deg about the parent's z.
  for (int f = 0; f < 10; ++f) {
    const double s = (f % 2 == 0) ? 1.0 : -1.0;
    const Quat q_world_torso(euler_xyz_to_rotation(Vec3(0.1 * f, -0.2, 0.05 * f)));
    const Vec3 t_world_torso(5.0 * f, 3, -1);
    const Quat q_torso_arm(rot_z(s * 0.2 * kRadPerDeg) * rot_x(0.7));
    const Vec3 t_torso_arm(20.0 + 0.5 * s, -30, 40);
    poses.push_back(pose(f, "torso", t_world_torso, q_world_torso));
    poses.push_back(pose(f, "upper_arm", t_world_torso + q_world_torso * t_torso_arm,
                         q_world_torso * q_torso_arm));
    AngleRow a;
    a.frame = f;
    a.joint = "shoulder";
    a.angles_deg = Vec3(10 + 0.3 * s, 20 - 0.3 * s, 30 + 0.3 * s);
    angles.push_back(a);
    a.joint = "elbow";
    a.type = JointType::kHinge;
    a.angles_deg = Vec3(45 + 0.05 * s, 0, 0);
    angles.push_back(a);
  }
  const auto r = joint_precision(model, poses, angles);
  ASSERT_EQ(r.size(), 2u);
  EXPECT_EQ(r[0].frames, 10);
  EXPECT_NEAR(r[0].translation_std_mm, 0.5, 1e-9);
  EXPECT_NEAR(r[0].rotation_std_deg, 0.2, 1e-6);
  EXPECT_NEAR(r[0].angle_std_deg, 0.3, 1e-9);
  EXPECT_EQ(r[1].frames, 0);  // no lower_arm poses
  EXPECT_NEAR(r[1].angle_std_deg, 0.05, 1e-9);
}

TEST(AngleErrors, HingeBiasAndBallGeodesic) {
  std::vector<AngleRow> truth, meas;
  for (int f = 0; f < 4; ++f) {
    AngleRow t;
    t.frame = f;
    t.joint = "shoulder";
    t.q_parent_child = Quat(rot_y(0.3 * f));
    truth.push_back(t);
    AngleRow m = t;
    m.q_parent_child = Quat(rot_y(0.3 * f) * rot_x(0.04 * kRadPerDeg));  // 0.04 deg off
    meas.push_back(m);
    t.joint = "elbow";
    t.type = JointType::kHinge;
    t.angles_deg = Vec3(10.0 * f, 0, 0);
    truth.push_back(t);
    m = t;
    m.angles_deg(0) += (f % 2 == 0) ? 0.3 : 0.1;  // bias 0.2, +-0.1 about it
    if (f != 3) meas.push_back(m);                // frame 3 missing
  }
  std::vector<AngleErrorSample> series;
  const auto r = angle_errors(truth, meas, &series);
  ASSERT_EQ(r.size(), 2u);
  EXPECT_EQ(r[0].joint, "shoulder");
  EXPECT_EQ(r[0].frames, 4);
  EXPECT_NEAR(r[0].rms_deg, 0.04, 1e-6);
  EXPECT_NEAR(r[0].max_deg, 0.04, 1e-6);
  EXPECT_EQ(r[1].frames, 3);
  EXPECT_NEAR(r[1].mean_deg, (0.3 + 0.1 + 0.3) / 3.0, 1e-12);
  EXPECT_NEAR(r[1].rms_deg, std::sqrt((0.09 + 0.01 + 0.09) / 3.0), 1e-12);
  EXPECT_NEAR(r[1].max_deg, 0.3, 1e-12);
  const double m = 0.7 / 3.0;
  EXPECT_NEAR(r[1].rms_debiased_deg,
              std::sqrt(((0.3 - m) * (0.3 - m) * 2 + (0.1 - m) * (0.1 - m)) / 3.0), 1e-9);
  EXPECT_EQ(series.size(), 7u);
  EXPECT_EQ(r[1].gross, 0);
  EXPECT_NEAR(r[1].rms_without_gross_deg, r[1].rms_deg, 1e-12);
}

TEST(AngleErrors, GrossErrorsCountedApart) {
  std::vector<AngleRow> truth, meas;
  for (int f = 0; f < 5; ++f) {
    AngleRow t;
    t.frame = f;
    t.joint = "elbow";
    t.type = JointType::kHinge;
    t.angles_deg = Vec3(20.0, 0, 0);
    truth.push_back(t);
    t.angles_deg(0) += (f == 2) ? 180.0 : 0.02;  // one flipped pose
    meas.push_back(t);
  }
  const auto r = angle_errors(truth, meas);
  ASSERT_EQ(r.size(), 1u);
  EXPECT_EQ(r[0].gross, 1);
  EXPECT_NEAR(r[0].rms_without_gross_deg, 0.02, 1e-9);
  EXPECT_NEAR(r[0].max_deg, 180.0, 1e-9);
}

TEST(Segments, ReadsAndRejects) {
  test::TempDir dir("eval");
  const std::string ok = dir.file("segments.csv");
  test::write_file(
      ok,
      "segment,kind,first_frame,last_frame,tx,ty,tz\n0,hold,0,4,0,-150,0\n1,move,5,14,0,0,0\n"
      "2,hold,15,19,0.5,250,-1\n");
  auto s = read_segments_csv(ok);
  ASSERT_TRUE(s) << s.error().message;
  ASSERT_EQ(s->size(), 3u);
  EXPECT_TRUE((*s)[2].hold);
  EXPECT_FALSE((*s)[1].hold);
  EXPECT_EQ((*s)[2].first_frame, 15);
  EXPECT_NEAR((*s)[2].t_robot_mm.x(), 0.5, 1e-12);
  const std::string bad = dir.file("bad.csv");
  test::write_file(bad, "segment,kind,first_frame,last_frame,tx,ty,tz\n0,stay,0,4,0,0,0\n");
  auto b = read_segments_csv(bad);
  ASSERT_FALSE(b);
  EXPECT_NE(b.error().message.find("line 2"), std::string::npos);
  EXPECT_FALSE(read_segments_csv(dir.file("missing.csv")));
}

}  // namespace
}  // namespace mocap
