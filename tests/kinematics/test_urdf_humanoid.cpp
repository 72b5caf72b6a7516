// The URDF of the whole robot (`mocap calibrate --urdf`, kinematics/urdf_writer.h) on the
// simulator's humanoid and its true model (gt/model_true.yaml; 15 bodies, 14 joints: 8
// ball + 6 hinge, one tree rooted at the pelvis): one link per body plus the ball joints'
// and hinges' intermediate links, every joint's parent and child right, one root; the
// file loads as a tree in urdfdom (check_urdf, when installed). The URDF read back
// (links, joints, origins, axes: a small reader of the elements the writer emits) and
// driven with the tracker's joint angles of a random pose reproduces every body's pose
// relative to the pelvis, so the joint names, frames and angle conventions all hold.
#include <gtest/gtest.h>

#include <cstdio>
#include <cstdlib>
#include <map>
#include <random>
#include <regex>
#include <set>
#include <string>
#include <vector>

#include "core/rotation.h"
#include "kinematics/joint_angles.h"
#include "kinematics/urdf_writer.h"
#include "sim/simulate.h"
#include "tests/support/test_support.h"

namespace mocap::kinematics {
namespace {

struct UrdfJoint {
  std::string name, type, parent, child;
  Vec3 xyz = Vec3::Zero(), rpy = Vec3::Zero(), axis = Vec3::Zero();
};

struct Urdf {
  std::vector<std::string> links;
  std::vector<UrdfJoint> joints;
};

Vec3 triple(const std::string& s) {
  Vec3 v = Vec3::Zero();
  std::sscanf(s.c_str(), "%lf %lf %lf", &v[0], &v[1], &v[2]);
  return v;
}

Urdf parse(const std::string& text) {
  Urdf u;
  const std::regex link_re("<link name=\"([^\"]+)\"\\s*/>");
  for (std::sregex_iterator it(text.begin(), text.end(), link_re), end; it != end; ++it)
    u.links.push_back((*it)[1]);
  const std::regex joint_re("<joint name=\"([^\"]+)\" type=\"([^\"]+)\">([\\s\\S]*?)</joint>");
  const std::regex parent_re("<parent link=\"([^\"]+)\"\\s*/>"),
      child_re("<child link=\"([^\"]+)\"\\s*/>");
  const std::regex origin_re("<origin xyz=\"([^\"]+)\" rpy=\"([^\"]+)\"\\s*/>");
  const std::regex axis_re("<axis xyz=\"([^\"]+)\"\\s*/>");
  for (std::sregex_iterator it(text.begin(), text.end(), joint_re), end; it != end; ++it) {
    UrdfJoint j;
    j.name = (*it)[1];
    j.type = (*it)[2];
    const std::string body = (*it)[3];
    std::smatch m;
    if (std::regex_search(body, m, parent_re)) j.parent = m[1];
    if (std::regex_search(body, m, child_re)) j.child = m[1];
    if (std::regex_search(body, m, origin_re)) {
      j.xyz = triple(m[1]);
      j.rpy = triple(m[2]);
    }
    if (std::regex_search(body, m, axis_re)) j.axis = triple(m[1]);
    u.joints.push_back(j);
  }
  return u;
}

struct Humanoid {
  sim::SimScene scene;
  Humanoid() {
    sim::SimOptions o;
    o.scene = sim::SceneKind::kHumanoid;
    o.cameras = 2;
    auto s = sim::make_scene(o);
    EXPECT_TRUE(s.ok()) << (s.ok() ? "" : s.error().message);
    if (s.ok()) scene = std::move(s).value();
  }
  std::size_t bodies() const { return scene.targets.bodies.size(); }
};

TEST(UrdfHumanoid, FifteenBodyLinksFourteenJointsOneTreeRootedAtThePelvis) {
  Humanoid h;
  ASSERT_EQ(h.bodies(), 15u);
  const JointModel& model = h.scene.joints_true;
  ASSERT_EQ(model.joints.size(), 14u);
  int balls = 0;
  for (const JointSpec& j : model.joints) balls += j.type == JointType::kBall;
  ASSERT_EQ(balls, 8);
  auto text = make_urdf(model, "humanoid", h.bodies());
  ASSERT_TRUE(text.ok()) << text.error().message;
  const Urdf u = parse(*text);
  // Links: the 15 bodies, 3 per ball joint (J_link_x, J_link_y, J_center), 1 per hinge
  // (J_axis); joints: 4 per ball (J_x, J_y, J_z revolute, J_fixed), 2 per hinge.
  EXPECT_EQ(u.links.size(), 15u + 3 * 8 + 6);
  EXPECT_EQ(u.joints.size(), 4u * 8 + 2 * 6);
  const std::set<std::string> links(u.links.begin(), u.links.end());
  EXPECT_EQ(links.size(), u.links.size()) << "a link named twice";
  for (const MarkerTarget& b : h.scene.targets.bodies) EXPECT_TRUE(links.count(b.name)) << b.name;
  EXPECT_FALSE(links.count("world")) << "one tree needs no world link";
  std::map<std::string, const UrdfJoint*> joint_of_child;
  std::set<std::string> joint_names;
  int revolute = 0;
  for (const UrdfJoint& j : u.joints) {
    EXPECT_TRUE(links.count(j.parent)) << j.name << " parent " << j.parent;
    EXPECT_TRUE(links.count(j.child)) << j.name << " child " << j.child;
    EXPECT_TRUE(joint_of_child.emplace(j.child, &j).second) << j.child << " has two parents";
    EXPECT_TRUE(joint_names.insert(j.name).second) << "joint " << j.name << " named twice";
    revolute += j.type == "revolute";
    if (j.type == "revolute") {
      EXPECT_NEAR(j.axis.norm(), 1.0, 1e-12) << j.name;
    }
  }
  EXPECT_EQ(revolute, 3 * 8 + 6);  // one per degree of freedom (the /joint_states names)
  std::vector<std::string> roots;
  for (const std::string& l : u.links)
    if (!joint_of_child.count(l)) roots.push_back(l);
  ASSERT_EQ(roots, std::vector<std::string>{"pelvis"});
  // Each mocap joint: from its child body up through its own chain to its parent body.
  for (const JointSpec& j : model.joints) {
    const std::vector<std::string> chain =
        j.type == JointType::kBall ? std::vector<std::string>{j.name + "_fixed", j.name + "_z",
                                                              j.name + "_y", j.name + "_x"}
                                   : std::vector<std::string>{j.name + "_fixed", j.name};
    std::string link = j.child;
    for (const std::string& expected : chain) {
      ASSERT_TRUE(joint_of_child.count(link)) << link;
      const UrdfJoint* uj = joint_of_child.at(link);
      EXPECT_EQ(uj->name, expected) << "above " << link;
      EXPECT_EQ(uj->type, expected == j.name + "_fixed" ? "fixed" : "revolute") << uj->name;
      link = uj->parent;
    }
    EXPECT_EQ(link, j.parent) << j.name;
  }
}

// Forward kinematics of the URDF read back: T_pelvis_link for every link, given the
// revolute joints' positions.
std::map<std::string, Iso3> urdf_fk(const Urdf& u, const std::map<std::string, double>& q) {
  std::map<std::string, Iso3> T;
  T["pelvis"] = Iso3::Identity();
  for (bool grew = true; grew;) {  // parents before children, whatever the file order
    grew = false;
    for (const UrdfJoint& j : u.joints) {
      if (T.count(j.child) || !T.count(j.parent)) continue;
      Iso3 origin = Iso3::Identity();
      origin.linear() = rot_z(j.rpy[2]) * rot_y(j.rpy[1]) * rot_x(j.rpy[0]);
      origin.translation() = j.xyz * 1e3;  // metres -> mm
      Iso3 motion = Iso3::Identity();
      if (j.type == "revolute")
        motion.linear() = Eigen::AngleAxisd(q.at(j.name), j.axis).toRotationMatrix();
      T[j.child] = T.at(j.parent) * origin * motion;
      grew = true;
    }
  }
  return T;
}

TEST(UrdfHumanoid, DrivenByTheTrackersAnglesItReproducesEveryBodyPose) {
  Humanoid h;
  const sim::SimScene& sc = h.scene;
  auto text = make_urdf(sc.joints_true, "humanoid", h.bodies());
  ASSERT_TRUE(text.ok()) << text.error().message;
  const Urdf u = parse(*text);
  auto solver = JointAngleSolver::create(sc.joints_true, h.bodies());
  ASSERT_TRUE(solver.ok()) << solver.error().message;
  JointAngles angles = solver->make_output();
  std::mt19937 rng(5);
  for (int trial = 0; trial < 5; ++trial) {
    sim::JointConfig config = sim::make_config(sc);
    for (int k = 0; k < sc.joint_count(); ++k) {
      const sim::SimJoint& j = sc.tree[static_cast<std::size_t>(k)];
      for (int a = 0; a < 3; ++a)
        config.q_rad[static_cast<std::size_t>(k)][a] =
            std::uniform_real_distribution<double>(j.lower_rad[a], j.upper_rad[a])(rng);
    }
    sim::SceneState state = sim::make_state(sc);
    sim::apply_config(sc, config, state);
    std::vector<BodyPoseView> views;
    for (const Iso3& T : state.T_world_body) views.push_back({true, T});
    solver->reset();
    ASSERT_TRUE(solver->compute(views.data(), angles));
    std::map<std::string, double> q;  // the /joint_states names and positions
    for (std::size_t j = 0; j < sc.joints_true.joints.size(); ++j) {
      const JointSpec& s = sc.joints_true.joints[j];
      const JointAngle& a = angles.joints[j];
      ASSERT_TRUE(a.valid);
      if (s.type == JointType::kHinge) {
        q[s.name] = a.a0;
      } else {
        q[s.name + "_x"] = a.a0;
        q[s.name + "_y"] = a.a1;
        q[s.name + "_z"] = a.a2;
      }
    }
    const auto T = urdf_fk(u, q);
    const Iso3 T_world_pelvis = state.T_world_body[0];
    ASSERT_EQ(sc.targets.bodies[0].name, "pelvis");
    for (std::size_t b = 0; b < h.bodies(); ++b) {
      const std::string& name = sc.targets.bodies[b].name;
      ASSERT_TRUE(T.count(name)) << name;
      const Iso3 truth = T_world_pelvis.inverse() * state.T_world_body[b];
      EXPECT_LT((T.at(name).linear() - truth.linear()).norm(), 1e-9) << name << " trial " << trial;
      EXPECT_LT((T.at(name).translation() - truth.translation()).norm(), 1e-6)
          << name << " trial " << trial;
    }
  }
}

TEST(UrdfHumanoid, LoadsAsOneTreeInUrdfdom) {
  Humanoid h;
  test::TempDir dir("kin_urdf_humanoid");
  const std::string path = dir.file("humanoid.urdf");
  ASSERT_TRUE(write_urdf(path, h.scene.joints_true, "humanoid", h.bodies()).ok());
  if (std::system("command -v check_urdf > /dev/null 2>&1") != 0)
    GTEST_SKIP() << "check_urdf (liburdfdom-tools) not on PATH: URDF not parsed";
  FILE* p = popen(("check_urdf " + path + " 2>&1").c_str(), "r");
  ASSERT_NE(p, nullptr);
  std::string output;
  char buf[4096];
  std::size_t n;
  while ((n = std::fread(buf, 1, sizeof buf, p)) > 0) output.append(buf, n);
  ASSERT_EQ(pclose(p), 0) << output;
  EXPECT_NE(output.find("Successfully Parsed XML"), std::string::npos) << output;
  EXPECT_NE(output.find("root Link: pelvis"), std::string::npos) << output;
  // urdfdom prints the tree below the root, one "child(k):  NAME" line per link: each of
  // the 44 other links exactly once.
  std::multiset<std::string> printed;
  const std::regex child_re("child\\(\\d+\\):\\s+(\\S+)");
  for (std::sregex_iterator it(output.begin(), output.end(), child_re), end; it != end; ++it)
    printed.insert((*it)[1]);
  auto text = make_urdf(h.scene.joints_true, "humanoid", h.bodies());
  ASSERT_TRUE(text.ok());
  std::multiset<std::string> expected;
  for (const std::string& l : parse(*text).links)
    if (l != "pelvis") expected.insert(l);
  EXPECT_EQ(printed.size(), 44u) << output;
  EXPECT_EQ(printed, expected) << output;
}

}  // namespace
}  // namespace mocap::kinematics
