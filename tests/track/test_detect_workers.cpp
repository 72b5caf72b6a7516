// ParallelDetect (the offline tracker's detection on two threads): every output file of
// `mocap track` is byte for byte the one-thread result, on a 4-camera recording of the
// shoulder rig and on the humanoid; under TSan (label concurrency) the handshake is
// race-free.
#include <gtest/gtest.h>

#include <fstream>
#include <sstream>
#include <string>

#include "tests/track/track_fixture.h"
#include "track/offline_tracker.h"

namespace mocap {
namespace {

std::string slurp(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

void expect_same_outputs(const std::string& rec) {
  test::TempDir one("detect_one"), two("detect_two");
  for (const auto& [threads, out] : {std::pair{1, one.path()}, std::pair{2, two.path()}}) {
    OfflineTrackOptions o;
    o.recording_dir = rec;
    o.targets_path = rec + "/targets.yaml";
    o.model_path = rec + "/gt/model_true.yaml";
    o.out_dir = out;
    o.detect_threads = threads;
    auto r = track_recording(o);
    ASSERT_TRUE(r.ok()) << r.error().message;
    EXPECT_GT(r->points, 0);
  }
  for (const char* f : {"points.csv", "poses.csv", "angles.csv", "markers.csv"}) {
    const std::string a = slurp(one.path() + "/" + f), b = slurp(two.path() + "/" + f);
    EXPECT_FALSE(a.empty()) << f;
    EXPECT_EQ(a, b) << f;
  }
}

TEST(ParallelDetect, SameOutputsAsOneThreadShoulderRig) {
  sim::SimOptions so;
  so.cameras = 4;
  so.frames = 12;
  expect_same_outputs(test::simulated_recording("detect_workers_ring4", so));
}

TEST(ParallelDetect, SameOutputsAsOneThreadHumanoid) {
  sim::SimOptions so;
  so.scene = sim::SceneKind::kHumanoid;
  so.cameras = 3;
  so.frames = 4;
  expect_same_outputs(test::simulated_recording("detect_workers_humanoid3", so));
}

}  // namespace
}  // namespace mocap
