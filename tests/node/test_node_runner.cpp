// Tests of the node's capture and detection (pipeline/node/node_runner.h) without a
// central: the central triggers are pushed by hand into the sender's trigger rings (the
// listener's side) and the messages read from its per-camera queues (the sender thread is
// not started). The detection workers of the `trigger: central` cameras play every
// camera's frame of every trigger, in trigger order, the replay's frame the trigger names
// (a skipped number is seeked over), with the same blob lists whatever the worker count;
// node.detect_threads' default and its bounds; a scheduled trigger fires at its instant,
// which the node takes on its own clock but never more than the lead after the arrival.
#include <gtest/gtest.h>
#include <unistd.h>

#include <chrono>
#include <cstring>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "core/clock.h"
#include "formats/recording.h"
#include "hal/replay_camera.h"
#include "pipeline/node/node_runner.h"

namespace mocap::node {
namespace {

#ifndef MOCAP_TEST_NODE_RECORDING
#define MOCAP_TEST_NODE_RECORDING "node_recording"
#endif

struct Message {
  WireHeader header;
  std::vector<std::uint8_t> blobs;
};

// `cameras` replay cameras of the fixture recording (`trigger: central`) on one node with
// `threads` detection workers; triggers `numbers` pushed at once (scheduled `ahead_ns[i]`
// after the push when given: the instants go to `instants`); each camera's messages.
class NodeRunnerTest : public ::testing::Test {
 protected:
  void SetUp() override {
    auto rec = Recording::open(MOCAP_TEST_NODE_RECORDING);
    ASSERT_TRUE(rec) << rec.error().message;
    recording_ = std::make_shared<const Recording>(std::move(rec).value());
  }
  std::vector<std::vector<Message>> play(int cameras, int threads,
                                         const std::vector<std::uint64_t>& numbers,
                                         int* workers = nullptr,
                                         const std::vector<std::int64_t>& ahead_ns = {},
                                         std::vector<std::int64_t>* instants = nullptr) {
    const auto domain = 1 + static_cast<std::uint32_t>((::getpid() * 11 + 5) % 231);
    auto sender = NodeSender::create(domain, std::vector<bool>(cameras, true), 8, false);
    EXPECT_TRUE(sender) << sender.error().message;
    if (!sender) return {};
    std::vector<std::unique_ptr<hal::ReplayCamera>> cams;
    std::vector<NodeCameraSpec> specs;
    for (int c = 0; c < cameras; ++c) {
      auto cam = hal::ReplayCamera::open(recording_, c, hal::ReplayPacing::kRecordedTiming);
      EXPECT_TRUE(cam) << cam.error().message;
      if (!cam) return {};
      hal::CameraConfig want = (*cam)->native_config();
      want.trigger = hal::TriggerMode::kSoftware;
      EXPECT_TRUE((*cam)->configure(want));
      NodeCameraSpec s;
      s.camera = cam->get();
      s.seekable = cam->get();
      s.name = "cam" + std::to_string(c);
      s.central = true;
      s.replay = true;
      specs.push_back(s);
      cams.push_back(std::move(cam).value());
    }
    NodeOptions opt;
    opt.node_name = "n0";
    opt.realtime = false;
    opt.detect_threads = threads;
    auto runner = NodeRunner::create(specs, detect::DetectorConfig{}, opt, **sender);
    EXPECT_TRUE(runner) << runner.error().message;
    if (!runner) return {};
    if (workers != nullptr) *workers = (*runner)->workers();
    EXPECT_TRUE((*runner)->start());
    const std::int64_t pushed_ns = monotonic_ns();
    for (std::size_t i = 0; i < numbers.size(); ++i) {
      const std::int64_t fire = ahead_ns.empty() ? 0 : pushed_ns + ahead_ns[i];
      if (instants != nullptr) instants->push_back(fire);
      for (int c = 0; c < cameras; ++c)
        EXPECT_TRUE((*sender)->triggers(c).try_push({numbers[i], 1, 2, fire}));
      (*sender)->trigger_bell().ring(cameras);
    }
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(20);
    while ((*runner)->published() < numbers.size() * static_cast<std::size_t>(cameras) &&
           std::chrono::steady_clock::now() < deadline)
      std::this_thread::sleep_for(std::chrono::milliseconds(5));
    (*runner)->stop();
    std::vector<std::vector<Message>> out(static_cast<std::size_t>(cameras));
    for (int c = 0; c < cameras; ++c) {
      while (const WireFrame* f = (*sender)->queue(c).front()) {
        Message m;
        m.header = f->header;
        m.blobs.assign(f->blobs, f->blobs + f->header.blob_count * kBlobRecordBytes);
        out[static_cast<std::size_t>(c)].push_back(std::move(m));
      }
    }
    return out;
  }
  std::shared_ptr<const Recording> recording_;
};

TEST_F(NodeRunnerTest, OneWorkerPlaysEveryCameraOfEveryTriggerInOrder) {
  const std::vector<std::uint64_t> numbers = {0, 1, 3, 4};  // 2 skipped: seeked over
  int workers = 0;
  const auto got = play(4, 1, numbers, &workers);
  EXPECT_EQ(workers, 1);
  ASSERT_EQ(got.size(), 4u);
  for (std::size_t c = 0; c < got.size(); ++c) {
    ASSERT_EQ(got[c].size(), numbers.size()) << "camera " << c;
    for (std::size_t i = 0; i < numbers.size(); ++i) {
      const WireHeader& h = got[c][i].header;
      EXPECT_EQ(h.frame_number, numbers[i]) << "camera " << c;
      EXPECT_EQ(h.capture_ns, recording_->frames()[numbers[i]].timestamp_ns) << "camera " << c;
      EXPECT_STREQ(h.camera, ("cam" + std::to_string(c)).c_str());
      EXPECT_EQ(h.flags & kWireMissing, 0) << "camera " << c;
      EXPECT_GT(h.blob_count, 0u) << "camera " << c << " frame " << numbers[i];
      EXPECT_EQ(h.health.frames, i + 1) << "camera " << c;
    }
  }
}

TEST_F(NodeRunnerTest, TheWorkerCountChangesNoBlob) {
  const std::vector<std::uint64_t> numbers = {0, 1, 2, 5, 6, 7};
  const auto one = play(4, 1, numbers);
  int workers = 0;
  const auto three = play(4, 3, numbers, &workers);
  EXPECT_EQ(workers, 3);
  ASSERT_EQ(one.size(), 4u);
  ASSERT_EQ(three.size(), 4u);
  for (std::size_t c = 0; c < one.size(); ++c) {
    ASSERT_EQ(one[c].size(), numbers.size()) << "camera " << c;
    ASSERT_EQ(three[c].size(), numbers.size()) << "camera " << c;
    for (std::size_t i = 0; i < numbers.size(); ++i) {
      EXPECT_EQ(three[c][i].header.frame_number, numbers[i]);
      EXPECT_EQ(three[c][i].header.blob_count, one[c][i].header.blob_count);
      EXPECT_EQ(three[c][i].blobs, one[c][i].blobs) << "camera " << c << " frame " << numbers[i];
    }
  }
}

TEST_F(NodeRunnerTest, AScheduledTriggerFiresAtItsInstantInOrder) {
  // Pushed together: an instant already past (fires at once), then two 200 and 400 ms
  // ahead. Every camera's frame of a trigger is detected after its instant and before
  // the next one's (the detection takes well under 200 ms), in order, on 1 or 2 workers.
  for (const int threads : {1, 2}) {
    std::vector<std::int64_t> instants;
    const auto got =
        play(3, threads, {0, 1, 2}, nullptr, {-5'000'000, 200'000'000, 400'000'000}, &instants);
    ASSERT_EQ(got.size(), 3u);
    ASSERT_EQ(instants.size(), 3u);
    for (std::size_t c = 0; c < got.size(); ++c) {
      ASSERT_EQ(got[c].size(), 3u) << "camera " << c;
      for (std::size_t i = 0; i < 3; ++i) {
        const WireHeader& h = got[c][i].header;
        EXPECT_EQ(h.frame_number, i);
        if (i > 0) {
          EXPECT_GE(h.detected_ns, instants[i]) << "camera " << c << " trigger " << i;
        }
        if (i < 2) {
          EXPECT_LT(h.detected_ns, instants[i + 1]) << "camera " << c << " trigger " << i;
        }
      }
    }
  }
}

TEST(NodeFireInstant, TheInstantOnThisClockNeverMoreThanTheLeadAfterTheArrival) {
  constexpr std::int64_t kMs = 1'000'000;
  const std::int64_t sent = 5'000 * kMs, mono = 77 * kMs;
  // Not scheduled: at once, nothing counted.
  FireInstant f = fire_instant(0, sent, sent + kMs, mono);
  EXPECT_EQ(f.mono_ns, 0);
  EXPECT_FALSE(f.late || f.unsynced);
  // Synchronised clocks, 1 ms lead, 0.1 ms on the way: 0.9 ms from now.
  f = fire_instant(sent + kMs, sent, sent + kMs / 10, mono);
  EXPECT_EQ(f.mono_ns, mono + 9 * kMs / 10);
  EXPECT_FALSE(f.late || f.unsynced);
  // Arrived after its instant: at once, late.
  f = fire_instant(sent + kMs, sent, sent + 2 * kMs, mono);
  EXPECT_EQ(f.mono_ns, 0);
  EXPECT_TRUE(f.late);
  // This clock 50 ms behind the central's: the instant seems 51 ms ahead; fired one lead
  // after the arrival instead, unsynced.
  f = fire_instant(sent + kMs, sent, sent - 50 * kMs, mono);
  EXPECT_EQ(f.mono_ns, mono + kMs);
  EXPECT_TRUE(f.unsynced);
  EXPECT_FALSE(f.late);
  // A hostile lead of an hour waits at most kMaxTriggerLeadUs; one before its own send
  // time fires at once.
  f = fire_instant(sent + 3'600'000 * kMs, sent, sent, mono);
  EXPECT_EQ(f.mono_ns, mono + kMaxTriggerLeadUs * 1000);
  EXPECT_TRUE(f.unsynced);
  f = fire_instant(sent - kMs, sent, sent - 2 * kMs, mono);
  EXPECT_EQ(f.mono_ns, mono);
  EXPECT_TRUE(f.unsynced);
}

TEST(NodeRunnerWorkers, DefaultIsTheCentralCamerasUpToTheOnlineCpus) {
  EXPECT_EQ(detect_workers(0, 4, 2), 2);
  EXPECT_EQ(detect_workers(0, 4, 16), 4);
  EXPECT_EQ(detect_workers(0, 1, 16), 1);
  EXPECT_EQ(detect_workers(1, 4, 16), 1);
  EXPECT_EQ(detect_workers(3, 4, 1), 3);  // given: as given
  EXPECT_EQ(detect_workers(0, 0, 4), 0);  // no central camera: no worker
}

TEST_F(NodeRunnerTest, RejectsMoreWorkersThanCentralCameras) {
  auto sender = NodeSender::create(1 + static_cast<std::uint32_t>((::getpid() * 13) % 231),
                                   {true, true}, 8, false);
  ASSERT_TRUE(sender) << sender.error().message;
  std::vector<std::unique_ptr<hal::ReplayCamera>> cams;
  std::vector<NodeCameraSpec> specs;
  for (int c = 0; c < 2; ++c) {
    auto cam = hal::ReplayCamera::open(recording_, c, hal::ReplayPacing::kRecordedTiming);
    ASSERT_TRUE(cam) << cam.error().message;
    ASSERT_TRUE((*cam)->configure((*cam)->native_config()));
    specs.push_back({cam->get(), "cam" + std::to_string(c), true, true, cam->get()});
    cams.push_back(std::move(cam).value());
  }
  NodeOptions opt;
  opt.node_name = "n0";
  opt.detect_threads = 3;
  auto runner = NodeRunner::create(specs, detect::DetectorConfig{}, opt, **sender);
  ASSERT_FALSE(runner);
  EXPECT_EQ(runner.error().message,
            "mocap node: node.detect_threads: 3 workers for 2 cameras with trigger: central");
}

}  // namespace
}  // namespace mocap::node
