// Design: import of camera intrinsics (and a stereo pair's relative pose) written by
// other tools, so that `mocap calibrate-rig` can start from them and write rig.yaml:
//  - OpenCV FileStorage YAML from cv::calibrateCamera (camera_matrix / cameraMatrix / K
//    / M, distortion_coefficients / distCoeffs / D, image_width / image_height or
//    imageSize) and from cv::stereoCalibrate (M1 D1 M2 D2 or K1 D1 K2 D2 or
//    cameraMatrix1/2 distCoeffs1/2, R, T). Matrices are `!!opencv-matrix` maps (rows,
//    cols, dt, data) or plain lists; the `%YAML:1.0` header that yaml-cpp rejects is
//    stripped first (the line count is kept for error messages).
//  - ROS camera_info YAML (camera_calibration_parsers): image_width, image_height,
//    camera_name, camera_matrix, distortion_model (plumb_bob, or rational_polynomial
//    with zero extra terms), distortion_coefficients, rectification_matrix,
//    projection_matrix. A left/right pair gives the relative pose from the
//    rectification rotations and the right projection's Tx (metres -> mm).
// Distortion: 4 or 5 coefficients [k1 k2 p1 p2 (k3)]; longer OpenCV vectors (8, 12, 14)
// are accepted only when the extra (rational, thin-prism, tilt) terms are zero.
// Units of T: OpenCV's T is in the calibration board's units, taken as millimetres.
#pragma once

#include <string>
#include <vector>

#include "camera/camera_model.h"
#include "core/expected.h"

namespace mocap {

enum class IntrinsicsFormat { kRigYaml, kOpenCv, kRosCameraInfo };

struct ImportedIntrinsics {
  IntrinsicsFormat format = IntrinsicsFormat::kOpenCv;
  // Intrinsics only (extrinsics identity); width/height 0 when the file has no size.
  std::vector<CameraModel> cameras;
  // Relative pose of camera 1: X_cam1 = R_1_0 X_cam0 + t_1_0_mm (when has_relative_pose).
  bool has_relative_pose = false;
  Mat3 R_1_0 = Mat3::Identity();
  Vec3 t_1_0_mm = Vec3::Zero();
};

Expected<ImportedIntrinsics> import_opencv_yaml(const std::string& path);
Expected<ImportedIntrinsics> import_ros_camera_info(const std::string& path);
// The relative pose of a ROS left/right pair (both files' rectification rotations and
// the right projection matrix); intrinsics of both.
Expected<ImportedIntrinsics> import_ros_stereo(const std::string& left_path,
                                               const std::string& right_path);
// Detects the format: rig.yaml (a `cameras` list), ROS (`distortion_model` or
// `camera_name` with `camera_matrix`), else OpenCV FileStorage.
Expected<ImportedIntrinsics> import_intrinsics(const std::string& path);

}  // namespace mocap
