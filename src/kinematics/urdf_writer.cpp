// Design: see urdf_writer.h. Plain string building with %.17g numbers (exact round trip).
#include "kinematics/urdf_writer.h"

#include <cmath>
#include <cstdio>
#include <fstream>
#include <numbers>

#include "kinematics/joint_frame.h"
#include "kinematics/kinematic_tree.h"

namespace mocap::kinematics {
namespace {

std::string g(double v) {
  char buf[40];
  std::snprintf(buf, sizeof(buf), "%.17g", v);
  return buf;
}

std::string vec(const Vec3& v) { return g(v[0]) + " " + g(v[1]) + " " + g(v[2]); }

// URDF rpy: R = Rz(yaw) * Ry(pitch) * Rx(roll) (fixed-axis roll, pitch, yaw), metres.
// The pitch from atan2 (well conditioned also near +-90 deg, where asin is not).
Vec3 rpy(const Mat3& R) {
  const double pitch = std::atan2(-R(2, 0), std::hypot(R(0, 0), R(1, 0)));
  if (std::abs(R(2, 0)) > 1.0 - 1e-12) {
    return Vec3(std::atan2(-R(1, 2), R(1, 1)), pitch, 0.0);
  }
  return Vec3(std::atan2(R(2, 1), R(2, 2)), pitch, std::atan2(R(1, 0), R(0, 0)));
}

std::string origin(const Iso3& T) {
  return "    <origin xyz=\"" + vec(T.translation() * 1e-3) + "\" rpy=\"" + vec(rpy(T.linear())) +
         "\"/>\n";
}

std::string link(const std::string& name) { return "  <link name=\"" + name + "\"/>\n"; }

std::string joint(const std::string& name, const std::string& type, const std::string& parent,
                  const std::string& child, const Iso3& T, const Vec3* axis, double lower,
                  double upper) {
  std::string s = "  <joint name=\"" + name + "\" type=\"" + type + "\">\n";
  s += "    <parent link=\"" + parent + "\"/>\n    <child link=\"" + child + "\"/>\n";
  s += origin(T);
  if (axis) {
    s += "    <axis xyz=\"" + vec(*axis) + "\"/>\n";
    s += "    <limit lower=\"" + g(lower) + "\" upper=\"" + g(upper) +
         "\" effort=\"0\" velocity=\"0\"/>\n";
  }
  return s + "  </joint>\n";
}

}  // namespace

Expected<std::string> make_urdf(const JointModel& model, const std::string& robot_name,
                                std::size_t num_bodies) {
  auto tree = build_tree(model, num_bodies, "model.yaml");
  if (!tree) return tree.error();
  constexpr double kPi = std::numbers::pi;
  std::string s =
      "<?xml version=\"1.0\"?>\n<!-- written by mocap calibrate: lengths in m, "
      "angles in rad; see docs/kinematics.md -->\n<robot name=\"" +
      robot_name + "\">\n";
  std::vector<std::string> body_names(num_bodies);
  for (const auto& j : model.joints) {
    if (!j.calibrated) return make_error("model.yaml", "joints." + j.name, "not calibrated");
    body_names[static_cast<std::size_t>(j.parent_index)] = j.parent;
    body_names[static_cast<std::size_t>(j.child_index)] = j.child;
  }
  for (std::size_t b = 0; b < num_bodies; ++b) {
    if (tree->used[b]) s += link(body_names[b]);
  }
  if (tree->roots.size() > 1) {
    s += link("world");
    for (int r : tree->roots) {
      const std::string& name = body_names[static_cast<std::size_t>(r)];
      s += joint("world_to_" + name, "floating", "world", name, Iso3::Identity(), nullptr, 0, 0);
    }
  }
  const Vec3 ex = Vec3::UnitX(), ey = Vec3::UnitY(), ez = Vec3::UnitZ();
  for (int ji : tree->joint_order) {
    const JointSpec& j = model.joints[static_cast<std::size_t>(ji)];
    if (j.type == JointType::kHinge) {
      const Iso3 Cp = make_hinge_frame(j.center_parent, j.axis_parent).T_body_joint;
      const Iso3 Cc = make_hinge_frame(j.center_child, j.axis_child).T_body_joint;
      const std::string axis_link = j.name + "_axis";
      s += link(axis_link);
      s += joint(j.name, "revolute", j.parent, axis_link, Cp, &ez, -kPi, kPi);
      s += joint(j.name + "_fixed", "fixed", axis_link, j.child, Cc.inverse(), nullptr, 0, 0);
    } else {
      const std::string lx = j.name + "_link_x", ly = j.name + "_link_y", lc = j.name + "_center";
      s += link(lx) + link(ly) + link(lc);
      Iso3 T = Iso3::Identity();
      T.translation() = j.center_parent;
      s += joint(j.name + "_x", "revolute", j.parent, lx, T, &ex, -kPi, kPi);
      s += joint(j.name + "_y", "revolute", lx, ly, Iso3::Identity(), &ey, -kPi / 2, kPi / 2);
      s += joint(j.name + "_z", "revolute", ly, lc, Iso3::Identity(), &ez, -kPi, kPi);
      Iso3 Tc = Iso3::Identity();
      Tc.translation() = -j.center_child;
      s += joint(j.name + "_fixed", "fixed", lc, j.child, Tc, nullptr, 0, 0);
    }
  }
  return s + "</robot>\n";
}

Expected<void> write_urdf(const std::string& path, const JointModel& model,
                          const std::string& robot_name, std::size_t num_bodies) {
  auto text = make_urdf(model, robot_name, num_bodies);
  if (!text) return text.error();
  std::ofstream f(path, std::ios::binary | std::ios::trunc);
  if (!f) return make_error(path, "", "cannot open for writing");
  f << *text;
  f.close();
  if (!f) return make_error(path, "", "write failed");
  return {};
}

}  // namespace mocap::kinematics
