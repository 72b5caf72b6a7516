// Design: `mocap calibrate-rig` end to end: importing an OpenCV stereo calibration into
// rig.yaml, and the one-line errors with exit code 2 (import without R/T, a missing
// wand file, a bad option, too few wand frames in a small drawn recording, a
// recording of 9 cameras).
#include <gtest/gtest.h>

#include <algorithm>

#include "formats/pgm.h"
#include "formats/recording.h"
#include "formats/rig_yaml.h"
#include "formats/wand_yaml.h"
#include "sim/simulate.h"
#include "sim/wand_sim.h"
#include "tests/rigcal/opencv_stereo_yaml.h"
#include "tests/support/test_support.h"

namespace mocap {
namespace {

const std::string kStereo = test::opencv_stereo_yaml(/*with_image_size=*/true, 5);

// A small wand recording drawn directly (discs at the wand's projections on a flat
// background): rendering with the simulator is too slow for a test under ASan.
void write_wand_recording(const std::string& dir, int frames) {
  const auto scene = sim::make_scene(sim::SimOptions{});
  ASSERT_TRUE(scene);
  const Rig& rig = scene->rig;
  std::filesystem::create_directories(dir + "/cam0");
  std::filesystem::create_directories(dir + "/cam1");
  ASSERT_TRUE(save_rig(dir + "/rig.yaml", rig));
  std::vector<FrameEntry> entries;
  for (int f = 0; f < frames; ++f) entries.push_back(FrameEntry{f, f * 10000000LL});
  ASSERT_TRUE(save_frames_csv(dir + "/frames.csv", entries));
  const CalibrationObjects obj = sim::default_calibration_objects();
  ASSERT_TRUE(save_calibration_objects(dir + "/wand.yaml", obj));
  for (int f = 0; f < frames; ++f) {
    const Iso3 T = sim::wand_pose(f, frames, 1);
    for (std::size_t c = 0; c < 2; ++c) {
      const CameraModel& cam = rig.cameras[c];
      Image img(cam.width, cam.height, PixelFormat::kMono8, 255);
      std::fill(img.data(), img.data() + cam.width * cam.height, std::uint8_t{12});
      for (double s : obj.wand.markers_mm) {
        Vec2 px;
        if (!project(cam, T * Vec3(s - 150.0, 0, 0), px)) continue;
        for (int y = static_cast<int>(px.y()) - 6; y <= static_cast<int>(px.y()) + 6; ++y) {
          for (int x = static_cast<int>(px.x()) - 6; x <= static_cast<int>(px.x()) + 6; ++x) {
            if (x < 0 || y < 0 || x >= cam.width || y >= cam.height) continue;
            if ((Vec2(x, y) - px).norm() <= 5.0) img.row8(y)[x] = 200;
          }
        }
      }
      ASSERT_TRUE(write_pgm(frame_file_path(dir, cam.name, f), img.view()));
    }
  }
}

TEST(CalibrateRigCli, ImportsOpenCvStereo) {
  test::TempDir dir("rigcli");
  test::write_file(dir.file("stereo.yml"), kStereo);
  auto r = test::run_mocap("calibrate-rig --intrinsics " + dir.file("stereo.yml") + " --out " +
                           dir.file("rig.yaml"));
  ASSERT_EQ(r.exit_code, 0) << r.output;
  auto rig = load_rig(dir.file("rig.yaml"));
  ASSERT_TRUE(rig) << rig.error().message;
  ASSERT_EQ(rig->cameras.size(), 2u);
  EXPECT_DOUBLE_EQ(rig->cameras[1].fx, 1288.7);
  EXPECT_NEAR(rig->cameras[1].t_cam_world.x(), -443.8, 1e-12);
  EXPECT_TRUE(rig->cameras[0].R_cam_world.isIdentity(0.0));
}

TEST(CalibrateRigCli, Errors) {
  test::TempDir dir("rigcli");
  std::string text = kStereo;
  text = text.substr(0, text.find("R: !!"));
  test::write_file(dir.file("nort.yml"), text);
  auto r = test::run_mocap("calibrate-rig --intrinsics " + dir.file("nort.yml") + " --out " +
                           dir.file("rig.yaml"));
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.output.find("nort.yml: R, T: missing"), std::string::npos) << r.output;

  write_wand_recording(dir.file("w"), 6);
  r = test::run_mocap("calibrate-rig " + dir.file("w") + " --wand " + dir.file("nope.yaml") +
                      " --out " + dir.file("rig.yaml"));
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.output.find("nope.yaml: cannot open"), std::string::npos) << r.output;
  r = test::run_mocap("calibrate-rig " + dir.file("w") + " --wand " + dir.file("w/wand.yaml") +
                      " --out " + dir.file("rig.yaml") + " --intrinsics-mode maybe");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.output.find("--intrinsics-mode: must be auto, refine or fixed"), std::string::npos);
  r = test::run_mocap("calibrate-rig " + dir.file("w") + " --wand " + dir.file("w/wand.yaml") +
                      " --out " + dir.file("rig.yaml") + " --rod-cut 75");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.output.find("--rod-cut: must be 20 to 60 degrees"), std::string::npos) << r.output;
  r = test::run_mocap("calibrate-rig " + dir.file("w") + " --wand " + dir.file("w/wand.yaml") +
                      " --out " + dir.file("rig.yaml"));
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.output.find(dir.file("w") + ": frames: too few frames"), std::string::npos)
      << r.output;
  EXPECT_EQ(std::count(r.output.begin(), r.output.end(), '\n'), 1) << r.output;
  EXPECT_FALSE(std::filesystem::exists(dir.file("rig.yaml")));
}

TEST(CalibrateRigCli, ThirtyThreeCameraRecordingIsAnError) {
  test::TempDir dir("rigcli");
  const auto scene = sim::make_scene(sim::SimOptions{});
  ASSERT_TRUE(scene);
  Rig rig;
  for (int c = 0; c < 33; ++c) {
    rig.cameras.push_back(scene->rig.cameras[0]);
    rig.cameras.back().name = "cam" + std::to_string(c);
    std::filesystem::create_directories(dir.file("w/cam" + std::to_string(c)));
  }
  ASSERT_TRUE(save_rig(dir.file("w/rig.yaml"), rig));
  ASSERT_TRUE(save_frames_csv(dir.file("w/frames.csv"), {FrameEntry{0, 0}}));
  ASSERT_TRUE(save_calibration_objects(dir.file("wand.yaml"), sim::default_calibration_objects()));
  auto r = test::run_mocap("calibrate-rig " + dir.file("w") + " --wand " + dir.file("wand.yaml") +
                           " --out " + dir.file("rig.yaml"));
  EXPECT_EQ(r.exit_code, 2);
  // The rig reader refuses more than 32 cameras before the calibration looks at them.
  EXPECT_NE(
      r.output.find(dir.file("w") + "/rig.yaml: cameras: 33 cameras, at most 32 are supported"),
      std::string::npos)
      << r.output;
  EXPECT_EQ(std::count(r.output.begin(), r.output.end(), '\n'), 1) << r.output;
}

}  // namespace
}  // namespace mocap
