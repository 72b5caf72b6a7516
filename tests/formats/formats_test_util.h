// Design: fixtures shared by the formats tests: a valid rig.yaml text and a rig to
// mutate, and a matcher-friendly helper that loads a YAML text and returns the error.
#pragma once

#include <string>

#include "camera/camera_model.h"
#include "core/rotation.h"

namespace mocap::test {

inline const char* kValidRigYaml = R"(cameras:
  - name: cam0
    width: 1032
    height: 776
    fx: 1290.3
    fy: 1290.3
    cx: 515.5
    cy: 387.5
    distortion: [-0.1, 0.05, 0.001, -0.002, 0.0]
    R: [1, 0, 0, 0, 1, 0, 0, 0, 1]
    t: [0, 0, 0]
  - name: cam1
    width: 1032
    height: 776
    fx: 1288.0
    fy: 1289.5
    cx: 516.1
    cy: 388.2
    distortion: [-0.09, 0.04, 0.0, 0.0, 0.001]
    R: [0.9659258262890683, 0, -0.25881904510252074, 0, 1, 0, 0.25881904510252074, 0, 0.9659258262890683]
    t: [-400, 0, 50]
)";

inline Rig make_test_rig() {
  Rig rig;
  for (int i = 0; i < 2; ++i) {
    CameraModel c;
    c.name = "cam" + std::to_string(i);
    c.width = 1032 + i;
    c.height = 776 - i;
    c.fx = 1290.3 + 0.1 * i;
    c.fy = 1290.7 - 0.3 * i;
    c.cx = 515.5 + 1.0 / 3.0;
    c.cy = 387.5 - 2.0 / 7.0;
    c.distortion = {-0.1234567890123, 0.05 + i * 1e-3, 1e-4, -2e-4, 1.0 / 3e3};
    c.R_cam_world = euler_xyz_to_rotation(Vec3(0.1 * i, -0.2 + 0.01 * i, 0.3));
    c.t_cam_world = Vec3(-400.0 * i + 0.1, 1.0 / 3.0, 1234.5678901234);
    rig.cameras.push_back(c);
  }
  return rig;
}

}  // namespace mocap::test
