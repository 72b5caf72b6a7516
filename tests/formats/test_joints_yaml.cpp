// Tests of joints.yaml / model.yaml: round trip with extras and every validation error.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "formats/joints_yaml.h"
#include "tests/support/test_support.h"

namespace mocap {
namespace {

using ::testing::HasSubstr;
using ::testing::StartsWith;

const char* kJoints = R"(joints:
  - name: shoulder
    type: ball
    parent: torso
    child: upper_arm
  - name: elbow
    type: hinge
    parent: upper_arm
    child: lower_arm
)";

const char* kModel = R"(joints:
  - name: shoulder
    type: ball
    parent: torso
    child: upper_arm
    center_parent: [100, 0, 0]
    center_child: [0, 0, 0]
    residual_rms_mm: 0.4
  - name: elbow
    type: hinge
    parent: upper_arm
    child: lower_arm
    center_parent: [200, 0, 0]
    center_child: [-20, 0, 0]
    axis_parent: [0, 0, 2]
    axis_child: [0, 1, 0]
    center_parent_std_mm: [0.1, 0.2, 0.3]
    note: "outside tool text, ignored"
)";

TargetSet make_targets() {
  TargetSet t;
  for (const char* n : {"torso", "upper_arm", "lower_arm"}) {
    t.bodies.push_back(MarkerTarget{n, {Vec3(0, 0, 0), Vec3(50, 0, 0), Vec3(0, 50, 0)}});
  }
  return t;
}

JointSpec make_joint(const char* name, JointType type, const char* parent, const char* child,
                     int parent_index, int child_index) {
  JointSpec j;
  j.name = name;
  j.type = type;
  j.parent = parent;
  j.child = child;
  j.parent_index = parent_index;
  j.child_index = child_index;
  return j;
}

class JointsYamlTest : public ::testing::Test {
 protected:
  test::TempDir dir{"joints_yaml"};
  std::string path = dir.file("model.yaml");
  TargetSet targets = make_targets();

  std::string error_of(const std::string& text, bool model) {
    test::write_file(path, text);
    auto r = model ? load_model(path, targets) : load_joints(path, targets);
    EXPECT_FALSE(r.ok());
    if (r.ok()) return {};
    EXPECT_EQ(r.error().message.find('\n'), std::string::npos);
    EXPECT_THAT(r.error().message, StartsWith(path + ": "));
    return r.error().message;
  }
  static std::string with(const char* base, const std::string& from, const std::string& to) {
    std::string s = base;
    const auto pos = s.find(from);
    EXPECT_NE(pos, std::string::npos) << from;
    if (pos != std::string::npos) s.replace(pos, from.size(), to);
    return s;
  }
};

TEST_F(JointsYamlTest, LoadsTopology) {
  test::write_file(path, kJoints);
  auto r = load_joints(path, targets);
  ASSERT_TRUE(r.ok()) << r.error().message;
  ASSERT_EQ(r->joints.size(), 2u);
  EXPECT_EQ(r->joints[1].name, "elbow");
  EXPECT_EQ(r->joints[1].type, JointType::kHinge);
  EXPECT_EQ(r->joints[1].parent_index, 1);
  EXPECT_EQ(r->joints[1].child_index, 2);
  EXPECT_FALSE(r->joints[0].calibrated);
  EXPECT_EQ(r->index_of("elbow"), 1);
  EXPECT_EQ(r->index_of("knee"), -1);
  EXPECT_STREQ(joint_type_name(JointType::kHinge), "hinge");
  EXPECT_STREQ(joint_type_name(JointType::kBall), "ball");
}

TEST_F(JointsYamlTest, ModelNeedsParameters) {
  EXPECT_THAT(error_of(kJoints, true), HasSubstr("joints[0].center_parent: missing key"));
}

TEST_F(JointsYamlTest, LoadsModelWithExtrasAndNormalisesAxes) {
  test::write_file(path, kModel);
  auto r = load_model(path, targets);
  ASSERT_TRUE(r.ok()) << r.error().message;
  const JointSpec& elbow = r->joints[1];
  EXPECT_TRUE(elbow.calibrated);
  EXPECT_EQ(elbow.center_child, Vec3(-20, 0, 0));
  EXPECT_EQ(elbow.axis_parent, Vec3(0, 0, 1));
  ASSERT_EQ(elbow.extra.size(), 1u);
  EXPECT_EQ(elbow.extra[0].first, "center_parent_std_mm");
  EXPECT_EQ(elbow.extra[0].second, (std::vector<double>{0.1, 0.2, 0.3}));
  ASSERT_EQ(r->joints[0].extra.size(), 1u);
  EXPECT_EQ(r->joints[0].extra[0].second, std::vector<double>{0.4});
  // joints.yaml reads parameters when present.
  auto j = load_joints(path, targets);
  ASSERT_TRUE(j.ok()) << j.error().message;
  EXPECT_TRUE(j->joints[1].calibrated);
}

TEST_F(JointsYamlTest, RoundTripWithExtrasIsExact) {
  JointModel m;
  JointSpec ball = make_joint("shoulder", JointType::kBall, "torso", "upper_arm", 0, 1);
  ball.calibrated = true;
  ball.center_parent = Vec3(100.0 / 3.0, -1e-7, 12345.678901);
  ball.center_child = Vec3(0.1, 0.2, 0.3);
  ball.extra = {{"residual_rms_mm", {0.4123456789}}, {"empty", {}}, {"cov", {1, 2, 3, 4, 5, 6}}};
  JointSpec hinge = make_joint("elbow", JointType::kHinge, "upper_arm", "lower_arm", 1, 2);
  hinge.calibrated = true;
  hinge.center_parent = Vec3(200, 1.0 / 7.0, 0);
  hinge.center_child = Vec3(-20, 0, 3);
  hinge.axis_parent = Vec3(1, 2, 3).normalized();
  hinge.axis_child = Vec3(-0.3, 0.1, 0.7).normalized();
  JointSpec topo = make_joint("wrist", JointType::kBall, "lower_arm", "torso", 2, 0);
  m.joints = {ball, hinge, topo};
  ASSERT_TRUE(save_model(path, m).ok());
  auto r = load_joints(path, targets);
  ASSERT_TRUE(r.ok()) << r.error().message;
  ASSERT_EQ(r->joints.size(), 3u);
  for (std::size_t i = 0; i < 3; ++i) {
    const JointSpec& a = m.joints[i];
    const JointSpec& b = r->joints[i];
    EXPECT_EQ(a.name, b.name);
    EXPECT_EQ(a.type, b.type);
    EXPECT_EQ(a.parent, b.parent);
    EXPECT_EQ(a.child, b.child);
    EXPECT_EQ(a.parent_index, b.parent_index);
    EXPECT_EQ(a.child_index, b.child_index);
    EXPECT_EQ(a.calibrated, b.calibrated);
    if (!a.calibrated) continue;
    EXPECT_EQ(a.center_parent, b.center_parent);
    EXPECT_EQ(a.center_child, b.center_child);
    if (a.type == JointType::kHinge) {
      EXPECT_EQ(a.axis_parent, b.axis_parent);
      EXPECT_EQ(a.axis_child, b.axis_child);
    }
    EXPECT_EQ(a.extra, b.extra);
  }
  // load_model rejects the uncalibrated wrist.
  auto mm = load_model(path, targets);
  ASSERT_FALSE(mm.ok());
  EXPECT_THAT(mm.error().message, HasSubstr("joints[2].center_parent: missing key"));
}

TEST_F(JointsYamlTest, SaveRejectsBadExtraKey) {
  JointModel m;
  JointSpec ball = make_joint("shoulder", JointType::kBall, "torso", "upper_arm", 0, 1);
  ball.calibrated = true;
  ball.extra = {{"center_parent", {1, 2, 3}}};
  m.joints = {ball};
  auto r = save_model(path, m);
  ASSERT_FALSE(r.ok());
  EXPECT_THAT(r.error().message, HasSubstr("center_parent: extra key name not allowed"));
}

TEST_F(JointsYamlTest, MissingJointsKey) {
  EXPECT_THAT(error_of("bodies: []\n", false), HasSubstr(": joints: missing key"));
}

TEST_F(JointsYamlTest, EmptyJoints) {
  EXPECT_THAT(error_of("joints: []\n", false), HasSubstr("joints: empty list"));
}

TEST_F(JointsYamlTest, UnknownBody) {
  EXPECT_THAT(error_of(with(kJoints, "child: lower_arm", "child: forearm"), false),
              HasSubstr("joints[1].child: unknown body 'forearm'"));
}

TEST_F(JointsYamlTest, ParentEqualsChild) {
  EXPECT_THAT(error_of(with(kJoints, "child: lower_arm", "child: upper_arm"), false),
              HasSubstr("joints[1].child: parent and child are the same body 'upper_arm'"));
}

TEST_F(JointsYamlTest, UnknownType) {
  EXPECT_THAT(error_of(with(kJoints, "type: hinge", "type: slider"), false),
              HasSubstr("joints[1].type: unknown joint type 'slider' (expected ball or hinge)"));
}

TEST_F(JointsYamlTest, DuplicateJointNames) {
  EXPECT_THAT(error_of(with(kJoints, "name: elbow", "name: shoulder"), false),
              HasSubstr("joints[1].name: duplicate joint name 'shoulder'"));
}

TEST_F(JointsYamlTest, MissingParent) {
  EXPECT_THAT(error_of(with(kJoints, "    parent: torso\n", ""), false),
              HasSubstr("joints[0].parent: missing key"));
}

TEST_F(JointsYamlTest, ModelMissingCenterChild) {
  EXPECT_THAT(error_of(with(kModel, "    center_child: [0, 0, 0]\n", ""), true),
              HasSubstr("joints[0].center_child: missing key"));
}

TEST_F(JointsYamlTest, ModelMissingAxis) {
  EXPECT_THAT(error_of(with(kModel, "    axis_child: [0, 1, 0]\n", ""), true),
              HasSubstr("joints[1].axis_child: missing key"));
}

TEST_F(JointsYamlTest, ZeroLengthAxis) {
  EXPECT_THAT(error_of(with(kModel, "axis_parent: [0, 0, 2]", "axis_parent: [0, 0, 0]"), true),
              HasSubstr("joints[1].axis_parent: zero-length axis"));
}

TEST_F(JointsYamlTest, CenterNotFinite) {
  EXPECT_THAT(
      error_of(with(kModel, "center_parent: [200, 0, 0]", "center_parent: [200, .inf, 0]"), true),
      HasSubstr("joints[1].center_parent[1]: not a finite number"));
}

TEST_F(JointsYamlTest, CenterWrongSize) {
  EXPECT_THAT(error_of(with(kModel, "center_parent: [200, 0, 0]", "center_parent: [200, 0]"), true),
              HasSubstr("joints[1].center_parent: expected 3 numbers, got 2"));
}

}  // namespace
}  // namespace mocap
