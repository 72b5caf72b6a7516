// Design: the calibrated model leaves the library through model.yaml (save_model /
// load_model with the extras) and a URDF (checked by urdfdom's check_urdf when it is on
// PATH); the URDF joint mapping is verified against the ground-truth relative poses.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>

#include "core/rotation.h"
#include "formats/joints_yaml.h"
#include "kinematics/calibrate.h"
#include "kinematics/joint_angles.h"
#include "kinematics/joint_frame.h"
#include "kinematics/urdf_writer.h"
#include "tests/kinematics/synthetic_chain.h"
#include "tests/support/test_support.h"

namespace mocap::kinematics {
namespace {

using testing::make_chain;
using testing::SyntheticChain;

TEST(ModelYaml, RoundTripWithExtras) {
  const SyntheticChain c = make_chain({});
  auto res = calibrate_joints(c.targets, c.topology, c.input);
  ASSERT_TRUE(res.ok()) << res.error().message;
  test::TempDir dir("kin_model");
  const std::string path = dir.file("model.yaml");
  auto saved = save_model(path, res->model);
  ASSERT_TRUE(saved.ok()) << saved.error().message;
  auto loaded = load_model(path, c.targets);
  ASSERT_TRUE(loaded.ok()) << loaded.error().message;
  ASSERT_EQ(loaded->joints.size(), 2u);
  for (std::size_t j = 0; j < 2; ++j) {
    const JointSpec& a = res->model.joints[j];
    const JointSpec& b = loaded->joints[j];
    EXPECT_EQ(a.name, b.name);
    EXPECT_EQ(a.type, b.type);
    EXPECT_TRUE(b.calibrated);
    EXPECT_LT((a.center_parent - b.center_parent).norm(), 1e-9);
    EXPECT_LT((a.center_child - b.center_child).norm(), 1e-9);
    if (a.type == JointType::kHinge) {
      EXPECT_LT((a.axis_parent - b.axis_parent).norm(), 1e-9);
      EXPECT_LT((a.axis_child - b.axis_child).norm(), 1e-9);
    }
    ASSERT_EQ(a.extra.size(), b.extra.size());
    for (std::size_t k = 0; k < a.extra.size(); ++k) {
      EXPECT_EQ(a.extra[k].first, b.extra[k].first);
      ASSERT_EQ(a.extra[k].second.size(), b.extra[k].second.size()) << a.extra[k].first;
      for (std::size_t i = 0; i < a.extra[k].second.size(); ++i) {
        EXPECT_NEAR(a.extra[k].second[i], b.extra[k].second[i],
                    1e-12 * (1.0 + std::abs(a.extra[k].second[i])));
      }
    }
  }
  // The loaded model drives the angle solver.
  EXPECT_TRUE(JointAngleSolver::create(*loaded, c.targets.bodies.size()).ok());
}

TEST(Urdf, JointMappingReproducesRelativePoses) {
  // Ball: T = Trans(c_p) Rx(a0) Ry(a1) Rz(a2) Trans(-c_c); hinge: C_p Rz(a0) C_c^-1.
  const SyntheticChain c = make_chain({});
  auto solver = JointAngleSolver::create(c.truth, 3);
  ASSERT_TRUE(solver.ok());
  JointAngles out = solver->make_output();
  const JointSpec& s = c.truth.joints[0];
  const JointSpec& e = c.truth.joints[1];
  const Iso3 Cp = make_hinge_frame(e.center_parent, e.axis_parent).T_body_joint;
  const Iso3 Cc = make_hinge_frame(e.center_child, e.axis_child).T_body_joint;
  for (const auto& T : c.T_world_body_true) {
    std::array<BodyPoseView, 3> v{{{true, T[0]}, {true, T[1]}, {true, T[2]}}};
    ASSERT_TRUE(solver->compute(v.data(), out));
    const Iso3 ball =
        Eigen::Translation3d(s.center_parent) *
        Iso3(euler_xyz_to_rotation(Vec3(out.joints[0].a0, out.joints[0].a1, out.joints[0].a2))) *
        Eigen::Translation3d(-s.center_child);
    EXPECT_LT((ball.matrix() - (T[0].inverse() * T[1]).matrix()).norm(), 1e-8);
    const Iso3 hinge = Cp * Iso3(rot_z(out.joints[1].a0)) * Cc.inverse();
    EXPECT_LT((hinge.matrix() - (T[1].inverse() * T[2]).matrix()).norm(), 1e-8);
  }
}

TEST(Urdf, WrittenFileParsesWithCheckUrdf) {
  const SyntheticChain c = make_chain({});
  auto text = make_urdf(c.truth, "arm", 3);
  ASSERT_TRUE(text.ok()) << text.error().message;
  for (const char* name : {"<link name=\"torso\"/>", "<joint name=\"elbow\" type=\"revolute\">",
                           "<joint name=\"shoulder_x\" type=\"revolute\">",
                           "<joint name=\"shoulder_fixed\" type=\"fixed\">"}) {
    EXPECT_NE(text->find(name), std::string::npos) << name;
  }
  test::TempDir dir("kin_urdf");
  const std::string path = dir.file("arm.urdf");
  ASSERT_TRUE(write_urdf(path, c.truth, "arm", 3).ok());
  EXPECT_EQ(test::read_file(path), *text);
  if (std::system("command -v check_urdf > /dev/null 2>&1") != 0) {
    GTEST_SKIP() << "check_urdf (liburdfdom-tools) not on PATH: URDF not parsed";
  }
  FILE* p = popen(("check_urdf " + path + " 2>&1").c_str(), "r");
  ASSERT_NE(p, nullptr);
  std::string output;
  char buf[4096];
  std::size_t n;
  while ((n = std::fread(buf, 1, sizeof buf, p)) > 0) output.append(buf, n);
  EXPECT_EQ(pclose(p), 0) << output;
  EXPECT_NE(output.find("Successfully Parsed XML"), std::string::npos) << output;
  EXPECT_NE(output.find("root Link: torso"), std::string::npos) << output;
}

TEST(Urdf, Errors) {
  const SyntheticChain c = make_chain({});
  JointModel m = c.truth;
  m.joints[0].calibrated = false;
  auto t = make_urdf(m, "arm", 3);
  ASSERT_FALSE(t.ok());
  EXPECT_EQ(t.error().message, "model.yaml: joints.shoulder: not calibrated");
  EXPECT_FALSE(write_urdf("/nonexistent-dir/x.urdf", c.truth, "arm", 3).ok());
}

}  // namespace
}  // namespace mocap::kinematics
