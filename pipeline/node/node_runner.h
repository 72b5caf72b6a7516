// Design: `mocap node`'s capture and detection (issue 29; docs/hal.md, "Camera nodes").
// The cameras with `trigger: central` are served by a pool of real-time detection workers
// (`mocap-ndet<k>`, NodeOptions::detect_threads, default min(those cameras, online CPUs)):
// the trigger listener pushes each central trigger into every such camera's SPSC ring and
// rings the workers' one doorbell (NodeSender); a woken worker first fires every pending
// trigger of the cameras no other worker holds (their exposures start together), then
// claims the cameras one at a time (a per-camera `held` flag: a camera is driven by one
// thread at a time, never two) and plays one frame of each: seek, dequeue, detect, pack
// the blob list into a WireFrame and push it to the camera's drop-oldest queue at once
// (NodeSender: DDS happens on the sender thread), release. After a pass over the cameras
// the worker wakes the sender once, which writes the pass's messages together (fewer
// wake-ups and datagrams than one per camera; the frame set waits for its last camera
// anyway). A worker that played a frame looks again before it sleeps, so a trigger that
// arrived while another worker held its camera is never left waiting; a worker that wakes
// late leaves its cameras to the others. A trigger the central scheduled (its instant,
// node.trigger_lead_us ahead) is fired at its instant, not on arrival: the worker sleeps
// until kFireSpinNs before it and spins the rest, so every camera of every node starts
// its exposure at the instant (within the clocks' synchronisation); one that arrives
// after its instant fires at once.
// Every other camera (its own software grid, external trigger, free run: its frames come
// on its own timing, and a blocking dequeue is its wait) has a thread of its own
// (`mocap-node<k>`). Each camera keeps its own BlobDetector, staging message and counters.
// A camera's end of stream (a replay's end) is sent as an end-of-stream message and ends
// its service. Frame numbers: a central-triggered camera's frame carries the number of
// the central trigger that released it (its own FIFO of received triggers, in order);
// any other camera's frame its own sequence number. A central-triggered replay plays the
// frame the trigger names (central trigger k: the recording's k-th frame,
// hal::ReplayCamera::seek), so a node started or restarted mid-run joins in step; the
// frames it passed over are counted (`skipped` in the report), and a trigger naming a
// frame already played (the central restarted, the node did not) is counted in `behind`
// and answered with the next frame, as before.
// The loops after start() are the hot path: noexcept, no allocation, no lock, no logging;
// their only syscalls are the camera's and the doorbells'. Health counters (lifetime; one
// writer at a time: the camera's holder, handed over through the `held` flag's release/
// acquire) travel in every message.
#pragma once

#include <atomic>
#include <climits>
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
  // Detection workers of the central-triggered cameras (node.detect_threads): 1..their
  // count; 0: min(their count, online CPUs).
  int detect_threads = 0;
};

// The detection workers node.detect_threads (0: the default) gives for `central` cameras
// with `trigger: central` and `cpus` online CPUs (0 without central cameras).
int detect_workers(int detect_threads, int central, int cpus) noexcept;

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
  int workers() const noexcept { return workers_; }  // detection workers (central cameras)
  std::string report() const;                        // one line per camera (report time)

 private:
  static constexpr std::int64_t kNoInstant = INT64_MAX;
  // The timer wake-up margin of a scheduled trigger: spinning costs a worker at most this
  // per trigger (2 % of a core at 100 Hz); a wake-up later than this fires late.
  static constexpr std::int64_t kFireSpinNs = 200'000;
  struct CamState {
    rt::Counter frames, errors, timeouts, overflow, triggers, behind;
    TriggerStamp staged;  // popped, its instant still ahead (has_staged)
    bool has_staged = false;
    TriggerStamp pending[64];  // central triggers sent to the camera, oldest first
    std::uint32_t head = 0, count = 0;
    bool behind_noted = false;  // behind counted for pending[head]
    bool ended = false;         // end of stream sent
    // A worker drives the camera (central cameras): claimed by exchange (acquire: the
    // previous holder's writes to the camera, this state and the queue are visible),
    // released by a release store.
    std::atomic<bool> held{false};
  };
  NodeRunner(std::vector<NodeCameraSpec> cameras, const NodeOptions& options, NodeSender& sender)
      : cams_(std::move(cameras)), options_(options), sender_(sender) {}
  const CamState& state(int c) const noexcept { return *states_[static_cast<std::size_t>(c)]; }
  CamState& state(int c) noexcept { return *states_[static_cast<std::size_t>(c)]; }
  void run(int c) noexcept;  // a camera's own thread (not central)
  void work() noexcept;      // a detection worker (the central cameras)
  bool claim(int c) noexcept;
  void unclaim(int c) noexcept;
  bool play(int c) noexcept;  // a held central camera's next frame; false: none pending
  // The dequeue's outcome: counted, sent, released. True when the stream ended.
  bool deliver(int c, hal::CameraStatus s, hal::Frame& f) noexcept;
  // Fires the camera's received triggers whose instant came, in order; returns the
  // instant of the first one still ahead (kNoInstant: none).
  std::int64_t take_triggers(int c) noexcept;
  // A worker with nothing to play until instant_ns (CLOCK_MONOTONIC).
  void wait_for(rt::Doorbell& bell, std::uint32_t seen, std::int64_t instant_ns) noexcept;
  void send(int c, const hal::Frame* f, std::uint16_t flags, const TriggerStamp& t) noexcept;

  std::vector<NodeCameraSpec> cams_;
  NodeOptions options_;
  NodeSender& sender_;
  std::vector<detect::BlobDetector> detectors_;
  std::vector<detect::BlobList> lists_;
  std::vector<std::unique_ptr<WireFrame>> staging_;  // per camera: the message being built
  std::vector<std::unique_ptr<CamState>> states_;
  std::vector<int> central_;  // the cameras the workers serve
  int workers_ = 0;
  std::vector<rt::RtThread> threads_;
  std::vector<std::string> notes_;
  std::atomic<bool> stop_{false};
  std::atomic<int> ended_{0};
  bool running_ = false;
};

}  // namespace mocap::node
