// The live pipeline on the replay camera gives the same body poses and joint angles as
// the offline tracker (`mocap track`, track_recording) on the same simulated recording:
// both run the same FrameProcessor stages, the pipeline split over its threads. Lockstep
// triggering makes the live run lossless, so temporal state evolves identically. The
// recording's end stops the triggering and finishes the run (no frame limit given).
// Replayed frames keep the recording's timestamps as their capture times, and their
// latencies start where the replay delivered them.
#include <gtest/gtest.h>

#include <cstdio>
#include <fstream>
#include <map>
#include <sstream>

#include "core/rotation.h"
#include "formats/joints_yaml.h"
#include "formats/recording.h"
#include "formats/targets_yaml.h"
#include "hal/replay_camera.h"
#include "pipeline/pipeline.h"
#include "sim/simulate.h"
#include "tests/pipeline/pipeline_fixture.h"
#include "tests/support/test_support.h"
#include "track/offline_tracker.h"

namespace mocap::pipeline {
namespace {

struct PoseKey {
  std::int64_t frame;
  std::string body;
  bool operator<(const PoseKey& o) const {
    return frame != o.frame ? frame < o.frame : body < o.body;
  }
};
struct PoseVal {
  double q[4], t[3];
};

std::map<PoseKey, PoseVal> read_poses_csv(const std::string& path) {
  std::map<PoseKey, PoseVal> out;
  std::ifstream f(path);
  std::string line;
  std::getline(f, line);  // header
  while (std::getline(f, line)) {
    std::stringstream ss(line);
    std::string cell;
    std::vector<std::string> cells;
    while (std::getline(ss, cell, ',')) cells.push_back(cell);
    if (cells.size() < 10) continue;
    PoseVal v{};
    for (int i = 0; i < 4; ++i) v.q[i] = std::stod(cells[static_cast<std::size_t>(3 + i)]);
    for (int i = 0; i < 3; ++i) v.t[i] = std::stod(cells[static_cast<std::size_t>(7 + i)]);
    out[{std::stoll(cells[0]), cells[2]}] = v;
  }
  return out;
}

class PoseObserver final : public FrameObserver {
 public:
  explicit PoseObserver(const TargetSet& targets) : targets_(targets) {}
  void observe(std::uint64_t sequence, std::int64_t, const FrameOutput& out) noexcept override {
    for (int b = 0; b < out.poses.count; ++b) {
      const BodyPose& body = out.poses.bodies[static_cast<std::size_t>(b)];
      if (!body.found) continue;
      const Quat q = canonical_quat(body.T_world_body.linear());
      PoseVal v{{q.w(), q.x(), q.y(), q.z()},
                {body.T_world_body.translation().x(), body.T_world_body.translation().y(),
                 body.T_world_body.translation().z()}};
      poses[{static_cast<std::int64_t>(sequence),
             targets_.bodies[static_cast<std::size_t>(b)].name}] = v;
    }
  }
  std::map<PoseKey, PoseVal> poses;  // the test thread reads it after stop()

 private:
  const TargetSet& targets_;
};

TEST(PipelineReplay, SamePosesAsOfflineTracking) {
  mocap::test::TempDir dir("pipeline_replay");
  const std::string rec_dir = dir.file("rec");
  sim::SimOptions so;
  so.frames = 25;
  ASSERT_TRUE(sim::write_simulated_recording(so, rec_dir).ok());

  OfflineTrackOptions to;
  to.recording_dir = rec_dir;
  to.targets_path = rec_dir + "/targets.yaml";
  to.model_path = rec_dir + "/gt/model_true.yaml";
  to.out_dir = dir.file("track");
  auto offline = track_recording(to);
  ASSERT_TRUE(offline.ok()) << offline.error().message;
  const auto want = read_poses_csv(dir.file("track/poses.csv"));
  ASSERT_GT(want.size(), 25u);

  auto rec = Recording::open(rec_dir);
  ASSERT_TRUE(rec.ok());
  auto shared = std::make_shared<const Recording>(std::move(rec).value());
  auto targets = load_targets(to.targets_path);
  ASSERT_TRUE(targets.ok());
  auto model = load_model(to.model_path, *targets);
  ASSERT_TRUE(model.ok());
  auto proc = FrameProcessor::create(shared->rig(), *targets, &*model, TrackerConfig{});
  ASSERT_TRUE(proc.ok());

  std::unique_ptr<hal::ReplayCamera> cams[2];
  for (int c = 0; c < 2; ++c) {
    auto cam = hal::ReplayCamera::open(shared, c, hal::ReplayPacing::kAsFastAsPossible);
    ASSERT_TRUE(cam.ok());
    cams[c] = std::move(cam).value();
    hal::CameraConfig cfg = cams[c]->native_config();
    cfg.trigger = hal::TriggerMode::kSoftware;
    cfg.buffer_count = 6;
    ASSERT_TRUE(cams[c]->configure(cfg).ok());
  }
  PoseObserver observer(*targets);
  test::RecordingSink sink(100);
  PipelineOptions opt = test::test_options();
  opt.pacing = TriggerPacing::kLockstep;
  opt.max_frames = 0;  // no limit: the recording's end ends the triggering (finished())
  opt.observer = &observer;
  auto p = Pipeline::create(std::move(proc).value(), {cams[0].get(), cams[1].get()}, {&sink}, opt);
  ASSERT_TRUE(p.ok());
  ASSERT_TRUE((*p)->start().ok());
  test::wait_finished(**p, 60.0);
  (*p)->stop();
  ASSERT_EQ(sink.count(), 25u);
  for (std::size_t i = 0; i < sink.count(); ++i) EXPECT_EQ(sink[i].sequence, i);

  ASSERT_EQ(observer.poses.size(), want.size());
  for (const auto& [key, w] : want) {
    auto it = observer.poses.find(key);
    ASSERT_NE(it, observer.poses.end()) << "frame " << key.frame << " body " << key.body;
    // poses.csv keeps 6 decimals for q and t.
    for (int i = 0; i < 4; ++i) EXPECT_NEAR(it->second.q[i], w.q[i], 2e-6);
    for (int i = 0; i < 3; ++i) EXPECT_NEAR(it->second.t[i], w.t[i], 2e-3);
  }
}

// A recording made on a host that had been up 1600 s longer than this one (its
// CLOCK_MONOTONIC timestamps 1600 s ahead of ours; the other way round, a recording from
// after boot replayed later, measured ~+1600 s before this fix): the published capture
// timestamps are the recording's, frame for frame, while every latency (detection,
// identification, trigger-to-publish) starts where the replay delivered the frame, so it
// is small and positive (interfaces.md, "The whole robot": replay cameras).
TEST(PipelineReplay, LatencyStartsAtTheDeliveryCaptureTimesAreTheRecordings) {
  mocap::test::TempDir dir("pipeline_replay_latency");
  const std::string rec_dir = dir.file("rec");
  sim::SimOptions so;
  so.frames = 6;
  ASSERT_TRUE(sim::write_simulated_recording(so, rec_dir).ok());
  auto frames = load_frames_csv(rec_dir + "/frames.csv");
  ASSERT_TRUE(frames.ok());
  const std::int64_t t0 = hal::monotonic_ns() + 1600'000'000'000;
  for (FrameEntry& e : *frames) e.timestamp_ns = t0 + e.frame * 10'000'000 + 17;
  ASSERT_TRUE(save_frames_csv(rec_dir + "/frames.csv", *frames).ok());

  auto rec = Recording::open(rec_dir);
  ASSERT_TRUE(rec.ok()) << rec.error().message;
  auto shared = std::make_shared<const Recording>(std::move(rec).value());
  auto targets = load_targets(rec_dir + "/targets.yaml");
  ASSERT_TRUE(targets.ok());
  auto model = load_model(rec_dir + "/gt/model_true.yaml", *targets);
  ASSERT_TRUE(model.ok());
  auto proc = FrameProcessor::create(shared->rig(), *targets, &*model, TrackerConfig{});
  ASSERT_TRUE(proc.ok());
  std::unique_ptr<hal::ReplayCamera> cams[2];
  for (int c = 0; c < 2; ++c) {
    auto cam = hal::ReplayCamera::open(shared, c, hal::ReplayPacing::kAsFastAsPossible);
    ASSERT_TRUE(cam.ok());
    cams[c] = std::move(cam).value();
    hal::CameraConfig cfg = cams[c]->native_config();
    cfg.trigger = hal::TriggerMode::kSoftware;
    cfg.buffer_count = 6;
    ASSERT_TRUE(cams[c]->configure(cfg).ok());
  }
  test::RecordingSink sink(16);
  PipelineOptions opt = test::test_options();
  opt.pacing = TriggerPacing::kLockstep;
  opt.max_frames = 0;
  auto p = Pipeline::create(std::move(proc).value(), {cams[0].get(), cams[1].get()}, {&sink}, opt);
  ASSERT_TRUE(p.ok());
  ASSERT_TRUE((*p)->start().ok());
  test::wait_finished(**p, 60.0);
  (*p)->stop();
  ASSERT_EQ(sink.count(), frames->size());
  for (std::size_t i = 0; i < sink.count(); ++i) {
    const client::JointsMessage& m = sink[i];
    ASSERT_LT(m.sequence, frames->size());
    EXPECT_EQ(m.capture_ns, (*frames)[static_cast<std::size_t>(m.sequence)].timestamp_ns);
    EXPECT_LT(m.publish_ns, m.capture_ns - 1500'000'000'000);  // published here and now
  }
  const PipelineStats stats = (*p)->stats();
  int checked = 0;
  for (const auto& [name, l] : stats.latency) {
    if (name != "detect0" && name != "detect1" && name != "identify" && name != "publish") continue;
    ++checked;
    EXPECT_EQ(l.count, frames->size()) << name;
    EXPECT_GT(l.p50_us, 0.0) << name;
    EXPECT_GT(l.mean_us, 0.0) << name;
    EXPECT_LT(l.max_us, 5e6) << name << ": measured from the recording's timestamps?";
  }
  EXPECT_EQ(checked, 4);
}

}  // namespace
}  // namespace mocap::pipeline
