// ParallelDetect (the offline tracker's detection on two threads): every output file of
// `mocap track` is byte for byte the one-thread result, on a 4-camera recording of the
// shoulder rig and on the humanoid; under TSan (label concurrency) the handshake is
// race-free; warm() without a frame, a frame after the worker's spin ran out, and a
// destruction while it spins neither hang nor change a frame's blobs.
#include <gtest/gtest.h>

#include <chrono>
#include <fstream>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "sim/frame_writer.h"
#include "sim/scene.h"
#include "sim/simulate.h"
#include "tests/track/track_fixture.h"
#include "track/detect_workers.h"
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

TEST(ParallelDetect, WarmBeforeLateOrNoFrameKeepsEveryFrameAndStops) {
  sim::SimOptions so;
  so.cameras = 4;
  auto scene = sim::make_scene(so);
  ASSERT_TRUE(scene.ok()) << scene.error().message;
  std::vector<Image> images = sim::make_camera_images(*scene);
  auto render = sim::MultiRender::create(*scene, 1);
  ASSERT_TRUE(render.ok()) << render.error().message;
  sim::SceneState state = sim::make_state(*scene);
  sim::apply_config(*scene, sim::make_config(*scene), state);
  ASSERT_TRUE(render->render(state, images).ok());
  std::vector<ImageView> views;
  for (const Image& im : images) views.push_back(im.view());
  std::vector<const ImageView*> ptrs;
  for (const ImageView& v : views) ptrs.push_back(&v);
  auto proc =
      FrameProcessor::create(scene->rig, scene->targets, &scene->joints_true, TrackerConfig{});
  ASSERT_TRUE(proc.ok()) << proc.error().message;
  FrameOutput ref = proc->make_output();
  FrameOutput out = proc->make_output();
  {
    // The reference: one thread.
    for (std::size_t c = 0; c < ptrs.size(); ++c) {
      ref.blobs[c].clear();
      proc->detect_camera(static_cast<int>(c), *ptrs[c], ref.blobs[c]);
    }
  }
  const auto same = [&] {
    for (std::size_t c = 0; c < ptrs.size(); ++c) {
      ASSERT_TRUE(out.camera_present[c]);
      ASSERT_EQ(out.blobs[c].size(), ref.blobs[c].size()) << "camera " << c;
    }
  };
  {
    ParallelDetect pd(*proc);
    pd.warm();  // a frame follows at once
    pd.detect(ptrs, out);
    same();
    pd.warm();  // no frame for longer than the worker spins
    std::this_thread::sleep_for(std::chrono::milliseconds(40));
    pd.detect(ptrs, out);
    same();
    for (int f = 0; f < 20; ++f) {  // frames with and without warm()
      if (f % 3 != 0) pd.warm();
      pd.detect(ptrs, out);
      same();
    }
    pd.warm();  // destroyed while the worker spins
  }
  EXPECT_GT(ref.blobs[0].size(), 0u);
}

}  // namespace
}  // namespace mocap
