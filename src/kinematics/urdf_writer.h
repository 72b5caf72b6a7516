// Design: URDF of a calibrated joint model (docs/kinematics.md, "URDF mapping").
//  - one <link> per body used by a joint, named like the body (no inertia or geometry:
//    the tracker knows kinematics only);
//  - hinge J: revolute joint J from the parent at frame C_parent (origin c_parent, rpy of
//    [c_x c_y c_z]), axis 0 0 1, to a link "J_axis"; a fixed joint "J_fixed" places the
//    child body at C_child^-1. The URDF joint position equals our hinge angle a0;
//  - ball J: revolutes "J_x", "J_y", "J_z" (axes x, y, z, all at the centre) through links
//    "J_link_x", "J_link_y", "J_center", then fixed "J_fixed" with origin -c_child. The
//    three positions equal our Euler angles (a0, a1, a2): R_rel = Rx(a0) Ry(a1) Rz(a2);
//  - more than one root body: a link "world" joins them with floating joints.
// Limits: revolute joints need them in URDF; we write [-pi, pi] ([-pi/2, pi/2] for the
// middle Euler angle) with effort = velocity = 0 (unknown to the tracker).
#pragma once

#include <string>

#include "core/expected.h"
#include "formats/joints_yaml.h"

namespace mocap::kinematics {

Expected<std::string> make_urdf(const JointModel& model, const std::string& robot_name,
                                std::size_t num_bodies);
Expected<void> write_urdf(const std::string& path, const JointModel& model,
                          const std::string& robot_name, std::size_t num_bodies);

}  // namespace mocap::kinematics
