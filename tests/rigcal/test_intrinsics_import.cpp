// Design: intrinsics import from files written by hand in the formats of OpenCV's
// FileStorage (cv::calibrateCamera's sample output with the %YAML:1.0 header and
// !!opencv-matrix nodes; cv::stereoCalibrate's M1 D1 M2 D2 R T) and ROS camera_info
// (single camera and a rectified left/right pair), and their malformed variants; plus
// the wand.yaml reader.
#include <gtest/gtest.h>

#include "formats/intrinsics_import.h"
#include "formats/wand_yaml.h"
#include "tests/rigcal/opencv_stereo_yaml.h"
#include "tests/support/test_support.h"

namespace mocap {
namespace {

const char* kOpenCvMono = R"(%YAML:1.0
---
calibration_time: "Mon 03 Nov 2026 10:12:01 UTC"
nr_of_frames: 25
image_width: 1032
image_height: 776
board_width: 9
board_height: 6
square_size: 25.
flags: 0
camera_matrix: !!opencv-matrix
   rows: 3
   cols: 3
   dt: d
   data: [ 1.2912e+03, 0., 5.1730000000000001e+02, 0., 1290.6,
       385.9, 0., 0., 1. ]
distortion_coefficients: !!opencv-matrix
   rows: 5
   cols: 1
   dt: d
   data: [ -1.2100000000000000e-01, 8.3e-02, 4.0e-04, -3.0e-04, 0. ]
avg_reprojection_error: 2.1e-01
)";

const std::string kOpenCvStereo = test::opencv_stereo_yaml(/*with_image_size=*/false, 8);

const char* kRosLeft = R"(image_width: 1032
image_height: 776
camera_name: left
camera_matrix:
  rows: 3
  cols: 3
  data: [1291.2, 0, 517.3, 0, 1290.6, 385.9, 0, 0, 1]
distortion_model: plumb_bob
distortion_coefficients:
  rows: 1
  cols: 5
  data: [-0.121, 0.083, 0.0004, -0.0003, 0]
rectification_matrix:
  rows: 3
  cols: 3
  data: [0.9816, 0, 0.1908, 0, 1, 0, -0.1908, 0, 0.9816]
projection_matrix:
  rows: 3
  cols: 4
  data: [1290, 0, 520, 0, 0, 1290, 388, 0, 0, 0, 1, 0]
)";

const char* kRosRight = R"(image_width: 1032
image_height: 776
camera_name: right
camera_matrix:
  rows: 3
  cols: 3
  data: [1288.7, 0, 513.8, 0, 1288.1, 389.4, 0, 0, 1]
distortion_model: plumb_bob
distortion_coefficients:
  rows: 1
  cols: 5
  data: [-0.118, 0.079, -0.0002, 0.0005, 0]
rectification_matrix:
  rows: 3
  cols: 3
  data: [0.9816, 0, -0.1908, 0, 1, 0, 0.1908, 0, 0.9816]
projection_matrix:
  rows: 3
  cols: 4
  data: [1290, 0, 520, -615.3, 0, 1290, 388, 0, 0, 0, 1, 0]
)";

std::string replace(std::string s, const std::string& a, const std::string& b) {
  const auto p = s.find(a);
  if (p != std::string::npos) s.replace(p, a.size(), b);
  return s;
}

TEST(IntrinsicsImport, OpenCvCalibrateCamera) {
  test::TempDir dir("import");
  test::write_file(dir.file("cam.yml"), kOpenCvMono);
  auto r = import_intrinsics(dir.file("cam.yml"));
  ASSERT_TRUE(r) << r.error().message;
  EXPECT_EQ(r->format, IntrinsicsFormat::kOpenCv);
  ASSERT_EQ(r->cameras.size(), 1u);
  const CameraModel& c = r->cameras[0];
  EXPECT_EQ(c.width, 1032);
  EXPECT_EQ(c.height, 776);
  EXPECT_DOUBLE_EQ(c.fx, 1291.2);
  EXPECT_DOUBLE_EQ(c.fy, 1290.6);
  EXPECT_DOUBLE_EQ(c.cx, 517.3);
  EXPECT_DOUBLE_EQ(c.cy, 385.9);
  EXPECT_DOUBLE_EQ(c.distortion[0], -0.121);
  EXPECT_DOUBLE_EQ(c.distortion[3], -0.0003);
  EXPECT_FALSE(r->has_relative_pose);
}

TEST(IntrinsicsImport, OpenCvStereoCalibrate) {
  test::TempDir dir("import");
  test::write_file(dir.file("stereo.yml"), kOpenCvStereo);
  auto r = import_opencv_yaml(dir.file("stereo.yml"));
  ASSERT_TRUE(r) << r.error().message;
  ASSERT_EQ(r->cameras.size(), 2u);
  EXPECT_DOUBLE_EQ(r->cameras[1].fx, 1288.7);
  EXPECT_DOUBLE_EQ(r->cameras[0].distortion[0], -0.121);
  EXPECT_EQ(r->cameras[0].width, 0);  // no size in the file
  ASSERT_TRUE(r->has_relative_pose);
  EXPECT_NEAR(r->t_1_0_mm.x(), -443.8, 1e-12);
  EXPECT_NEAR(r->R_1_0(0, 2), -0.3663, 1e-4);
}

TEST(IntrinsicsImport, RosCameraInfoAndPair) {
  test::TempDir dir("import");
  test::write_file(dir.file("left.yaml"), kRosLeft);
  test::write_file(dir.file("right.yaml"), kRosRight);
  auto l = import_intrinsics(dir.file("left.yaml"));
  ASSERT_TRUE(l) << l.error().message;
  EXPECT_EQ(l->format, IntrinsicsFormat::kRosCameraInfo);
  EXPECT_EQ(l->cameras[0].name, "left");
  EXPECT_DOUBLE_EQ(l->cameras[0].fx, 1291.2);
  auto pair = import_ros_stereo(dir.file("left.yaml"), dir.file("right.yaml"));
  ASSERT_TRUE(pair) << pair.error().message;
  // B = 615.3 / 1290 m = 477 mm; X_r = R_r^T (R_l X_l - B e_x).
  EXPECT_NEAR(pair->t_1_0_mm.norm(), 615.3 / 1290.0 * 1000.0, 1e-9);
  Mat3 Rl, Rr;
  Rl << 0.9816, 0, 0.1908, 0, 1, 0, -0.1908, 0, 0.9816;
  Rr << 0.9816, 0, -0.1908, 0, 1, 0, 0.1908, 0, 0.9816;
  EXPECT_LT((pair->R_1_0 - Rr.transpose() * Rl).norm(), 1e-3);
  EXPECT_LT((pair->R_1_0 * pair->R_1_0.transpose() - Mat3::Identity()).norm(), 1e-12);
  EXPECT_LT(pair->t_1_0_mm.x(), 0.0);
}

TEST(IntrinsicsImport, MalformedFiles) {
  test::TempDir dir("import");
  struct Case {
    std::string name, text, expect;
  };
  const std::vector<Case> cases = {
      {"rows.yml", replace(kOpenCvMono, "   rows: 3\n   cols: 3", "   rows: 2\n   cols: 3"),
       "camera_matrix: expected a 3x3 matrix, got 2x3"},
      {"short.yml", replace(kOpenCvMono, "385.9, 0., 0., 1. ]", "385.9, 0., 0. ]"),
       "camera_matrix.data"},
      {"fx.yml", replace(kOpenCvMono, "1.2912e+03", "-5"), "focal lengths must be > 0"},
      {"nodist.yml", replace(kOpenCvMono, "distortion_coefficients", "dist_x"),
       "distortion_coefficients: missing key"},
      {"rational.yml",
       replace(kOpenCvStereo, "0.0004, -0.0003, 0., 0., 0., 0.",
               "0.0004, -0.0003, 0., 0.2, 0., 0."),
       "D1: coefficient 5 is non-zero"},
      {"rot.yml", replace(kOpenCvStereo, "0.9305, 0., -0.3663", "0.5, 0., -0.3663"),
       "R: not a rotation matrix"},
      {"dt.yml", replace(kOpenCvMono, "dt: d", "dt: u"), "element type 'u'"},
      {"nan.yml", replace(kOpenCvMono, "385.9", ".nan"), "camera_matrix.data"},
      {"none.yml", "%YAML:1.0\n---\nfoo: 1\n", "camera_matrix: missing key"},
      {"empty.yml", "", "empty file"},
      {"broken.yml", "%YAML:1.0\n---\ncamera_matrix: [1, 2\n", "line"},
      {"ros_model.yaml", replace(kRosLeft, "plumb_bob", "equidistant"),
       "distortion_model: 'equidistant' is not supported"},
      {"ros_size.yaml", replace(kRosLeft, "image_width: 1032\n", ""), "image_width: missing key"},
  };
  for (const Case& c : cases) {
    test::write_file(dir.file(c.name), c.text);
    auto r = import_intrinsics(dir.file(c.name));
    ASSERT_FALSE(r) << c.name;
    EXPECT_NE(r.error().message.find(dir.file(c.name) + ": "), std::string::npos) << c.name;
    EXPECT_NE(r.error().message.find(c.expect), std::string::npos)
        << c.name << ": " << r.error().message;
    EXPECT_EQ(r.error().message.find('\n'), std::string::npos) << c.name;
  }
  EXPECT_FALSE(import_intrinsics(dir.file("missing.yml")));
  test::write_file(dir.file("right_noP.yaml"), replace(kRosRight, "-615.3", "615.3"));
  test::write_file(dir.file("left.yaml"), kRosLeft);
  auto p = import_ros_stereo(dir.file("left.yaml"), dir.file("right_noP.yaml"));
  ASSERT_FALSE(p);
  EXPECT_NE(p.error().message.find("P[0][3]"), std::string::npos);
}

TEST(WandYaml, RoundTripAndErrors) {
  test::TempDir dir("wand");
  CalibrationObjects obj;
  obj.wand.markers_mm = {0.0, 110.0, 300.0};
  obj.has_lframe = true;
  obj.lframe.markers_mm = {Vec3(0, 0, 0), Vec3(400, 0, 0), Vec3(0, 250, 0)};
  ASSERT_TRUE(save_calibration_objects(dir.file("w.yaml"), obj));
  auto r = load_calibration_objects(dir.file("w.yaml"));
  ASSERT_TRUE(r) << r.error().message;
  EXPECT_EQ(r->wand.markers_mm, obj.wand.markers_mm);
  EXPECT_EQ(r->lframe.markers_mm.size(), 3u);
  const std::vector<std::pair<std::string, std::string>> bad = {
      {"wand: {markers_mm: [0, 150, 300]}\n", "symmetric"},
      {"wand: {markers_mm: [0, 300]}\n", "needs 3..8"},
      {"wand: {markers_mm: [0, 5, 300]}\n", "at least 1.5 marker diameters"},
      {"wand: {markers_mm: [0, 110, 300]}\nlframe: {markers_mm: [[0,0,0],[100,0,0],[200,0,0]]}\n",
       "collinear"},
      {"wond: {}\n", "wand: missing key"},
  };
  for (const auto& [text, expect] : bad) {
    test::write_file(dir.file("b.yaml"), text);
    auto e = load_calibration_objects(dir.file("b.yaml"));
    ASSERT_FALSE(e) << text;
    EXPECT_NE(e.error().message.find(expect), std::string::npos) << e.error().message;
  }
}

}  // namespace
}  // namespace mocap
