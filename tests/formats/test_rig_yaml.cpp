// Tests of rig.yaml: exact round trip, and one test per validation error checking that
// the message names the file, the key and the problem.
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <sys/stat.h>

#include <cmath>

#include "formats/rig_yaml.h"
#include "tests/formats/formats_test_util.h"
#include "tests/support/test_support.h"

namespace mocap {
namespace {

using ::testing::AllOf;
using ::testing::HasSubstr;
using ::testing::StartsWith;

class RigYamlTest : public ::testing::Test {
 protected:
  test::TempDir dir{"rig_yaml"};
  std::string path = dir.file("rig.yaml");

  // Loads `text` (expected to fail) and returns the error message.
  std::string error_of(const std::string& text) {
    test::write_file(path, text);
    auto r = load_rig(path);
    EXPECT_FALSE(r.ok());
    if (r.ok()) return {};
    EXPECT_EQ(r.error().message.find('\n'), std::string::npos) << "one line";
    EXPECT_THAT(r.error().message, StartsWith(path + ": "));
    return r.error().message;
  }
  // kValidRigYaml with the first occurrence of `from` replaced by `to`.
  static std::string valid_with(const std::string& from, const std::string& to) {
    std::string s = test::kValidRigYaml;
    const auto pos = s.find(from);
    EXPECT_NE(pos, std::string::npos) << from;
    if (pos != std::string::npos) s.replace(pos, from.size(), to);
    return s;
  }
};

TEST_F(RigYamlTest, LoadsTheSpecExample) {
  test::write_file(path, test::kValidRigYaml);
  auto r = load_rig(path);
  ASSERT_TRUE(r.ok()) << r.error().message;
  ASSERT_EQ(r->cameras.size(), 2u);
  const CameraModel& c = r->cameras[1];
  EXPECT_EQ(c.name, "cam1");
  EXPECT_EQ(c.width, 1032);
  EXPECT_EQ(c.height, 776);
  EXPECT_EQ(c.fx, 1288.0);
  EXPECT_EQ(c.fy, 1289.5);
  EXPECT_EQ(c.cx, 516.1);
  EXPECT_EQ(c.cy, 388.2);
  EXPECT_EQ(c.distortion[0], -0.09);
  EXPECT_EQ(c.distortion[4], 0.001);
  EXPECT_EQ(c.R_cam_world(0, 2), -0.25881904510252074);
  EXPECT_EQ(c.R_cam_world(2, 0), 0.25881904510252074);
  EXPECT_EQ(c.t_cam_world, Vec3(-400, 0, 50));
}

TEST_F(RigYamlTest, RoundTripIsExact) {
  const Rig rig = test::make_test_rig();
  ASSERT_TRUE(save_rig(path, rig).ok());
  auto r = load_rig(path);
  ASSERT_TRUE(r.ok()) << r.error().message;
  ASSERT_EQ(r->cameras.size(), rig.cameras.size());
  for (std::size_t i = 0; i < rig.cameras.size(); ++i) {
    const CameraModel& a = rig.cameras[i];
    const CameraModel& b = r->cameras[i];
    EXPECT_EQ(a.name, b.name);
    EXPECT_EQ(a.width, b.width);
    EXPECT_EQ(a.height, b.height);
    EXPECT_EQ(a.fx, b.fx);
    EXPECT_EQ(a.fy, b.fy);
    EXPECT_EQ(a.cx, b.cx);
    EXPECT_EQ(a.cy, b.cy);
    EXPECT_EQ(a.distortion, b.distortion);
    EXPECT_EQ(a.R_cam_world, b.R_cam_world);
    EXPECT_EQ(a.t_cam_world, b.t_cam_world);
  }
  // Saving what was loaded gives the same text.
  const std::string first = test::read_file(path);
  ASSERT_TRUE(save_rig(path, *r).ok());
  EXPECT_EQ(test::read_file(path), first);
}

TEST_F(RigYamlTest, QuotedNamesRoundTrip) {
  Rig rig = test::make_test_rig();
  rig.cameras[0].name = "left cam #1";
  rig.cameras[1].name = "true";
  ASSERT_TRUE(save_rig(path, rig).ok());
  auto r = load_rig(path);
  ASSERT_TRUE(r.ok()) << r.error().message;
  EXPECT_EQ(r->cameras[0].name, "left cam #1");
  EXPECT_EQ(r->cameras[1].name, "true");
}

TEST_F(RigYamlTest, EveryTruncationLoadsOrFailsWithOneLine) {
  ASSERT_TRUE(save_rig(path, test::make_test_rig()).ok());
  const std::string full = test::read_file(path);
  int failures = 0;
  for (std::size_t n = 0; n < full.size(); n += 3) {
    test::write_file(path, full.substr(0, n));
    auto r = load_rig(path);
    if (r.ok()) continue;
    ++failures;
    EXPECT_THAT(r.error().message, StartsWith(path + ": "));
    EXPECT_EQ(r.error().message.find('\n'), std::string::npos);
  }
  EXPECT_GT(failures, 0);
}

TEST_F(RigYamlTest, MissingFile) {
  auto r = load_rig(dir.file("nope.yaml"));
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.error().message, dir.file("nope.yaml") + ": cannot open: No such file or directory");
}

TEST_F(RigYamlTest, UnreadableFileIsADirectory) {
  ::mkdir(dir.file("adir").c_str(), 0755);
  auto r = load_rig(dir.file("adir"));
  ASSERT_FALSE(r.ok());
  EXPECT_THAT(r.error().message, StartsWith(dir.file("adir") + ": cannot"));
}

TEST_F(RigYamlTest, EmptyFile) { EXPECT_THAT(error_of(""), HasSubstr("empty file")); }

TEST_F(RigYamlTest, YamlSyntaxErrorNamesTheLine) {
  const std::string msg = error_of("cameras:\n  - name: cam0\n    width: [1, 2\n");
  EXPECT_THAT(msg, HasSubstr(": line "));
}

TEST_F(RigYamlTest, TopLevelNotAMap) {
  EXPECT_THAT(error_of("- 1\n- 2\n"), AllOf(HasSubstr("top level"), HasSubstr("expected a map")));
}

TEST_F(RigYamlTest, MissingCameras) {
  EXPECT_THAT(error_of("cams: []\n"), AllOf(HasSubstr(": cameras: missing key")));
}

TEST_F(RigYamlTest, CamerasNotAList) {
  EXPECT_THAT(error_of("cameras:\n  name: cam0\n"),
              AllOf(HasSubstr("cameras: expected a list, got a map")));
}

TEST_F(RigYamlTest, EmptyCameras) {
  EXPECT_THAT(error_of("cameras: []\n"), AllOf(HasSubstr("cameras: empty list")));
}

TEST_F(RigYamlTest, ThirtyTwoCamerasAtMost) {
  Rig rig = test::make_test_rig();
  while (rig.cameras.size() < 33) {
    CameraModel c = rig.cameras[0];
    c.name = "cam" + std::to_string(rig.cameras.size());
    rig.cameras.push_back(c);
  }
  const std::string file = dir.file("thirty-three.yaml");
  ASSERT_TRUE(save_rig(file, rig).ok());
  auto r = load_rig(file);
  ASSERT_FALSE(r.ok());
  EXPECT_THAT(r.error().message,
              AllOf(StartsWith(file + ": cameras: 33 cameras, at most 32 are supported")));
  rig.cameras.pop_back();
  ASSERT_TRUE(save_rig(file, rig).ok());
  auto most = load_rig(file);
  ASSERT_TRUE(most.ok()) << most.error().message;
  EXPECT_EQ(most->cameras.size(), 32u);
}

TEST_F(RigYamlTest, MissingKeyNamesCameraAndKey) {
  EXPECT_THAT(error_of(valid_with("    fy: 1289.5\n", "")),
              HasSubstr("cameras[1].fy: missing key"));
  EXPECT_THAT(error_of(valid_with("    distortion: [-0.1, 0.05, 0.001, -0.002, 0.0]\n", "")),
              HasSubstr("cameras[0].distortion: missing key"));
}

TEST_F(RigYamlTest, StringWhereNumberExpected) {
  EXPECT_THAT(
      error_of(valid_with("fx: 1290.3", "fx: abc")),
      AllOf(HasSubstr("cameras[0].fx: expected a number, got 'abc'"), HasSubstr("(line 5)")));
}

TEST_F(RigYamlTest, NonIntegerWidth) {
  EXPECT_THAT(error_of(valid_with("width: 1032", "width: 1032.5")),
              HasSubstr("cameras[0].width: expected an integer, got '1032.5'"));
}

TEST_F(RigYamlTest, MapWhereListExpected) {
  EXPECT_THAT(error_of(valid_with("t: [0, 0, 0]", "t: {x: 0, y: 0, z: 0}")),
              HasSubstr("cameras[0].t: expected a list of 3 numbers, got a map"));
}

TEST_F(RigYamlTest, RWithEightValues) {
  EXPECT_THAT(error_of(valid_with("R: [1, 0, 0, 0, 1, 0, 0, 0, 1]", "R: [1, 0, 0, 0, 1, 0, 0, 0]")),
              HasSubstr("cameras[0].R: expected 9 numbers, got 8"));
}

TEST_F(RigYamlTest, DistortionWithFourValues) {
  EXPECT_THAT(error_of(valid_with("distortion: [-0.1, 0.05, 0.001, -0.002, 0.0]",
                                  "distortion: [-0.1, 0.05, 0.001, -0.002]")),
              HasSubstr("cameras[0].distortion: expected 5 numbers, got 4"));
}

TEST_F(RigYamlTest, RNotARotationSaysByHowMuch) {
  EXPECT_THAT(
      error_of(valid_with("R: [1, 0, 0, 0, 1, 0, 0, 0, 1]", "R: [1, 0, 0, 0, 1.01, 0, 0, 0, 1]")),
      AllOf(HasSubstr("cameras[0].R: not a rotation"), HasSubstr("0.0201")));
}

TEST_F(RigYamlTest, RReflectionRejected) {
  EXPECT_THAT(
      error_of(valid_with("R: [1, 0, 0, 0, 1, 0, 0, 0, 1]", "R: [1, 0, 0, 0, 1, 0, 0, 0, -1]")),
      AllOf(HasSubstr("cameras[0].R: not a rotation"), HasSubstr("det = -1")));
}

TEST_F(RigYamlTest, RoundedRotationIsReorthonormalised) {
  // Rz(30 deg) written with 4 decimals: orthonormality error ~5e-5.
  test::write_file(path, valid_with("R: [1, 0, 0, 0, 1, 0, 0, 0, 1]",
                                    "R: [0.8660, -0.5, 0, 0.5, 0.8660, 0, 0, 0, 1]"));
  auto r = load_rig(path);
  ASSERT_TRUE(r.ok()) << r.error().message;
  const Mat3& R = r->cameras[0].R_cam_world;
  EXPECT_TRUE(is_rotation(R, 1e-12));
  EXPECT_NEAR(R(0, 0), std::cos(M_PI / 6), 1e-4);
  EXPECT_NEAR(R(1, 0), 0.5, 1e-4);
}

TEST_F(RigYamlTest, NanAndInfRejected) {
  EXPECT_THAT(error_of(valid_with("cx: 515.5", "cx: .nan")),
              HasSubstr("cameras[0].cx: not a finite number: '.nan'"));
  EXPECT_THAT(error_of(valid_with("t: [0, 0, 0]", "t: [0, -.inf, 0]")),
              HasSubstr("cameras[0].t[1]: not a finite number: '-.inf'"));
  EXPECT_THAT(error_of(valid_with("fx: 1290.3", "fx: .Inf")),
              HasSubstr("cameras[0].fx: not a finite number"));
}

TEST_F(RigYamlTest, NonPositiveSizesAndFocalLengths) {
  EXPECT_THAT(error_of(valid_with("width: 1032", "width: 0")),
              HasSubstr("cameras[0].width: must be in 1..16384 pixels, got 0"));
  EXPECT_THAT(error_of(valid_with("height: 776", "height: -5")),
              HasSubstr("cameras[0].height: must be in 1..16384 pixels, got -5"));
  EXPECT_THAT(error_of(valid_with("fx: 1290.3", "fx: 0")), HasSubstr("cameras[0].fx: must be > 0"));
  EXPECT_THAT(error_of(valid_with("fy: 1289.5", "fy: -1289.5")),
              HasSubstr("cameras[1].fy: must be > 0, got -1289.5"));
}

TEST_F(RigYamlTest, DuplicateCameraNames) {
  EXPECT_THAT(error_of(valid_with("name: cam1", "name: cam0")),
              HasSubstr("cameras[1].name: duplicate camera name 'cam0'"));
}

TEST_F(RigYamlTest, CameraNameMustBeAFolderName) {
  EXPECT_THAT(error_of(valid_with("name: cam1", "name: a/b")),
              HasSubstr("cameras[1].name: name 'a/b' contains"));
}

TEST_F(RigYamlTest, DuplicateKeyRejected) {
  EXPECT_THAT(error_of(valid_with("    fy: 1289.5\n", "    fy: 1289.5\n    fy: 1.0\n")),
              HasSubstr("cameras[1].fy: duplicate key"));
}

TEST_F(RigYamlTest, UnknownKeysAreIgnored) {
  test::write_file(path,
                   std::string("serial: 1234\n") +
                       valid_with("    fy: 1289.5\n", "    fy: 1289.5\n    exposure_us: 800\n"));
  auto r = load_rig(path);
  ASSERT_TRUE(r.ok()) << r.error().message;
  EXPECT_EQ(r->cameras[1].fy, 1289.5);
}

}  // namespace
}  // namespace mocap
