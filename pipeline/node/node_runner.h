// Design: `mocap node`'s capture and detection (issue 29; docs/hal.md, "Camera nodes").
// One real-time thread per camera (`mocap-node<k>`, 1..8 cameras) drives its camera and
// its own BlobDetector: trigger (its own software grid, or each central trigger for
// `trigger: central`), dequeue, detect, pack the blob list into a WireFrame, push it to
// the camera's drop-oldest queue (NodeSender: DDS happens on the sender thread), release.
// A camera's end of stream (a replay's end) is sent as an end-of-stream message and ends
// that thread. Frame numbers: a central-triggered camera's frame carries the number of
// the central trigger that released it (its own FIFO of received triggers, in order);
// any other camera's frame its own sequence number. A central-triggered replay plays the
// frame the trigger names (central trigger k: the recording's k-th frame,
// hal::ReplayCamera::seek), so a node started or restarted mid-run joins in step; the
// frames it passed over are counted (`skipped` in the report), and a trigger naming a
// frame already played (the central restarted, the node did not) is counted in `behind`
// and answered with the next frame, as before.
// The loop after start() is the hot path: noexcept, no allocation, no lock, no logging;
// its only syscalls are the camera's and the doorbell's. Health counters (lifetime, this
// thread the only writer) travel in every message.
#pragma once

#include <atomic>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "detect/blob_detector.h"
#include "hal/camera.h"
#include "hal/replay_camera.h"
#include "pipeline/node/node_sender.h"
#include "rt/thread.h"

namespace mocap::node {

struct NodeCameraSpec {
  hal::Camera* camera = nullptr;  // configured, not started; outlives the runner
  std::string name;               // published camera name
  bool central = false;           // trigger: central
  bool replay = false;            // capture_ns is a recording's timestamp
  // The same camera when it is a replay that `central` makes follow the central's
  // trigger numbers (seek); null otherwise.
  hal::ReplayCamera* seekable = nullptr;
};

struct NodeOptions {
  std::string node_name;
  double trigger_rate_hz = 100.0;  // software-triggered cameras that are not central
  bool realtime = true;            // SCHED_FIFO for the camera threads (fallback noted)
};

class NodeRunner {
 public:
  static Expected<std::unique_ptr<NodeRunner>> create(std::vector<NodeCameraSpec> cameras,
                                                      const detect::DetectorConfig& detect,
                                                      const NodeOptions& options,
                                                      NodeSender& sender);
  ~NodeRunner();

  Expected<void> start();  // starts the cameras and their threads; notes() has fallbacks
  void stop() noexcept;    // joins the threads, stops the cameras
  // Every camera's stream ended (replays).
  bool finished() const noexcept {
    return ended_.load(std::memory_order_acquire) == static_cast<int>(cams_.size());
  }
  std::uint64_t frames(int c) const noexcept { return state(c).frames.get(); }
  std::uint64_t published() const noexcept;
  const std::vector<std::string>& notes() const noexcept { return notes_; }
  std::string report() const;  // one line per camera (report time)

 private:
  struct CamState {
    rt::Counter frames, errors, timeouts, overflow, triggers, behind;
    TriggerStamp pending[64];  // central triggers sent to the camera, oldest first
    std::uint32_t head = 0, count = 0;
    bool behind_noted = false;  // behind counted for pending[head]
  };
  NodeRunner(std::vector<NodeCameraSpec> cameras, const NodeOptions& options, NodeSender& sender)
      : cams_(std::move(cameras)), options_(options), sender_(sender) {}
  const CamState& state(int c) const noexcept { return *states_[static_cast<std::size_t>(c)]; }
  void run(int c) noexcept;
  void take_triggers(int c) noexcept;
  void send(int c, const hal::Frame* f, std::uint16_t flags, const TriggerStamp& t) noexcept;

  std::vector<NodeCameraSpec> cams_;
  NodeOptions options_;
  NodeSender& sender_;
  std::vector<detect::BlobDetector> detectors_;
  std::vector<detect::BlobList> lists_;
  std::vector<std::unique_ptr<WireFrame>> staging_;  // per camera: the message being built
  std::vector<std::unique_ptr<CamState>> states_;
  std::vector<rt::RtThread> threads_;
  std::vector<std::string> notes_;
  std::atomic<bool> stop_{false};
  std::atomic<int> ended_{0};
  bool running_ = false;
};

}  // namespace mocap::node
