// `mocap preview` end to end on the built-in simulated cameras, configured as on the
// first day (cameras only: no rig, no targets, no model): one PNG overlay per camera,
// preview.json with the counts against the thresholds, a summary and a recommendation
// line per camera; bad input is a one-line error.
#include <gtest/gtest.h>

#include <filesystem>

#include "tests/support/test_support.h"

namespace mocap::test {
namespace {

TEST(PreviewCli, SimCamerasGiveOverlaysAndASummary) {
  TempDir dir("preview");
  write_file(dir.file("cameras.yaml"),
             "version: 1\ncameras:\n  - {backend: sim, trigger: software}\n"
             "  - {backend: sim, trigger: external}\n");  // no targets exist yet
  const RunResult r = run_mocap("preview --config " + dir.file("cameras.yaml") + " --out " +
                                    dir.file("p") + " --loop-frames 2",
                                120);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  for (const char* cam : {"cam0", "cam1"}) {
    const std::string png = read_file(dir.file(std::string("p/") + cam + ".png"));
    ASSERT_GT(png.size(), 1000u) << cam;
    EXPECT_EQ(png.substr(1, 3), "PNG");
    EXPECT_NE(r.output.find(std::string(cam) + ": "), std::string::npos) << r.output;
  }
  // The simulated scene is well exposed: markers accepted, a recommendation per camera.
  EXPECT_NE(r.output.find("accepted (area"), std::string::npos) << r.output;
  const std::string json = read_file(dir.file("p/preview.json"));
  EXPECT_NE(json.find("\"camera\": \"cam0\""), std::string::npos) << json;
  EXPECT_NE(json.find("\"verdict\": \"accepted\""), std::string::npos);
  EXPECT_NE(json.find("\"recommendation\": "), std::string::npos);
  EXPECT_EQ(json.find("\"accepted\": 0,"), std::string::npos) << "no marker accepted";
}

TEST(PreviewCli, BadInputIsOneLineError) {
  TempDir dir("preview_bad");
  for (const std::string& args :
       {std::string("preview --out ") + dir.file("p") + " --frames 0",
        std::string("preview --frames 1"),
        std::string("preview --config ") + dir.file("none.yaml") + " --out " + dir.file("p")}) {
    const RunResult r = run_mocap(args, 30);
    EXPECT_EQ(r.exit_code, 2) << args << "\n" << r.output;
    EXPECT_EQ(line_count(r.output), 1) << args << "\n" << r.output;
  }
}

}  // namespace
}  // namespace mocap::test
