// Design: the cv::stereoCalibrate output shared by the intrinsics-import tests and the
// `mocap calibrate-rig --intrinsics` tests, written by hand in OpenCV FileStorage's
// format (%YAML:1.0 header, !!opencv-matrix nodes; M1 D1 M2 D2 R T). Camera 1:
// fx 1288.7; R a 21.5 degree turn about y; T (-443.8, 0, 174.7) mm.
#pragma once

#include <string>

namespace mocap::test {

// with_image_size: add image_width/image_height (1032x776) as the OpenCV sample does;
// d1_coefficients: D1's length, 5 or 8 (the rational model, its extra terms zero).
inline std::string opencv_stereo_yaml(bool with_image_size, int d1_coefficients) {
  std::string d1 = "-0.121, 0.083, 0.0004, -0.0003, 0.";
  for (int k = 5; k < d1_coefficients; ++k) d1 += ", 0.";
  return std::string("%YAML:1.0\n---\n") +
         (with_image_size ? "image_width: 1032\nimage_height: 776\n" : "") + R"(M1: !!opencv-matrix
   rows: 3
   cols: 3
   dt: d
   data: [ 1291.2, 0., 517.3, 0., 1290.6, 385.9, 0., 0., 1. ]
D1: !!opencv-matrix
   rows: 1
   cols: )" +
         std::to_string(d1_coefficients) + "\n   dt: d\n   data: [ " + d1 + R"( ]
M2: !!opencv-matrix
   rows: 3
   cols: 3
   dt: d
   data: [ 1288.7, 0., 513.8, 0., 1288.1, 389.4, 0., 0., 1. ]
D2: !!opencv-matrix
   rows: 1
   cols: 5
   dt: d
   data: [ -0.118, 0.079, -0.0002, 0.0005, 0. ]
R: !!opencv-matrix
   rows: 3
   cols: 3
   dt: d
   data: [ 0.9305, 0., -0.3663, 0., 1., 0., 0.3663, 0., 0.9305 ]
T: !!opencv-matrix
   rows: 3
   cols: 1
   dt: d
   data: [ -443.8, 0., 174.7 ]
)";
}

}  // namespace mocap::test
