// Design: the central tracker's side of the camera nodes (issue 29): one NodeLink per
// `mocap run` (shared by its NodeCameras, node_camera.h) holds the DDS participant and
//   - the mocap/blobs listener, the receiver (called by Cyclone where it delivers a
//     message: its receive thread, SCHED_FIFO kDdsFifoPriority when realtime, node_dds.h;
//     no thread hop; its calls never overlap): takes the samples, finds the camera by
//     (node, camera) name, checks and decodes the message (node_wire.h: malformed and
//     oversized messages are counted per node and dropped) into a slot of that camera's
//     inbox (rt::SlotPool, receiver -> capture thread; inbox full: counted, dropped),
//     estimates the node's clock offset and rings the inbox doorbell;
//   - the trigger thread (`mocap-ntrig`, SCHED_FIFO kDdsFifoPriority when realtime): writes
//     mocap/trigger for every central trigger the capture thread posts (trigger(): an SPSC
//     ring, never DDS on the capture thread). With a trigger lead (node.trigger_lead_us) the
//     capture thread posts each trigger that long before its instant, and the message
//     carries the instant (`fire_ns`, CLOCK_REALTIME): the nodes fire their cameras then,
//     together, whatever the trigger's way took (a scheduled trigger, as GigE Vision's
//     scheduled action commands: the exposures of all nodes start within their clocks'
//     synchronisation, and the trigger's way is off the frame's latency).
// Clock offset per node (CLOCK_REALTIME, node minus central), NTP-style from a trigger's
// round trip: t0 central sent, t1 node received, t2 node sent, t3 central received:
// offset = ((t1 - t0) + (t2 - t3)) / 2, round trip = (t3 - t0) - (t2 - t1); the sample
// with the smallest round trip of the last 256 wins. Without triggers: t2 - t3 (one way).
// node_work (the node's leg) starts at the later of t1 and the trigger's instant.
// start() waits (bounded) until every node of the configuration was discovered.
#pragma once

#include <atomic>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "core/latency_histogram.h"
#include "detect/blob.h"
#include "pipeline/node/node_dds.h"
#include "rt/counter.h"
#include "rt/doorbell.h"
#include "rt/slot_pool.h"
#include "rt/spsc_ring.h"
#include "rt/thread.h"

namespace mocap::node {

// One received message in a camera's inbox.
struct Received {
  WireHeader header;
  detect::BlobList blobs;
  std::int64_t received_ns = 0;  // central CLOCK_MONOTONIC
};

struct NodeStats {
  std::string name;
  rt::Counter messages, malformed, oversized;
  std::atomic<std::int64_t> offset_ns{0};                // node minus central CLOCK_REALTIME
  std::atomic<std::int64_t> round_trip_ns{-1};           // of that estimate; -1: one-way / none
  std::int64_t window_best_rtt = -1, window_offset = 0;  // the receiver
  int window_count = 0;
};

class NodeLink {
 public:
  // realtime: its threads and Cyclone's receive thread at SCHED_FIFO kDdsFifoPriority.
  // trigger_lead_ns: how long before its instant a central trigger is posted (0: at it).
  static Expected<std::shared_ptr<NodeLink>> create(std::uint32_t domain_id, double wait_s,
                                                    bool realtime,
                                                    std::int64_t trigger_lead_ns = 0);
  ~NodeLink();

  // Setup (before start): camera `camera` of node `node`; its inbox holds `slots`
  // messages of up to `max_blobs` blobs. Returns the camera's index here.
  Expected<int> add_camera(const std::string& node, const std::string& camera, std::uint32_t slots,
                           int max_blobs);
  rt::SlotPool<Received>& inbox(int k) noexcept { return *inboxes_[static_cast<std::size_t>(k)]; }
  rt::Doorbell& bell() noexcept { return bell_; }

  // Reference-counted by the cameras' start()/stop(): the first start starts the trigger
  // thread and the receiver and waits for the nodes; one line on nodes not seen (and on
  // what of realtime was not applied) goes to notice(). The last stop returns once no
  // receiver call runs.
  Expected<void> start();
  void stop() noexcept;
  const std::string& notice() const noexcept { return notice_; }

  // Capture thread: posts central trigger `number`, to fire at `at_ns` (CLOCK_MONOTONIC;
  // 0: when it arrives) once: later calls with the same or a lower number are ignored.
  void trigger(std::uint64_t number, std::int64_t at_ns) noexcept;
  std::int64_t trigger_lead_ns() const noexcept { return trigger_lead_ns_; }

  // Any thread: the highest frame number + 1 any camera's (valid, not end-of-stream)
  // message carried. A NodeCamera declares a frame missing only below it: some node got
  // that trigger and answered (so the replays' end, answered by end-of-stream messages
  // only, never becomes a frame of missing cameras).
  std::uint64_t received_end() const noexcept {
    return received_end_.load(std::memory_order_acquire);  // pairs with on_sample()
  }
  std::uint64_t unknown() const noexcept { return unknown_.get(); }
  std::uint64_t inbox_full(int k) const noexcept {
    return full_[static_cast<std::size_t>(k)]->get();
  }
  const std::vector<std::unique_ptr<NodeStats>>& nodes() const noexcept { return nodes_; }
  const LatencyHistogram& transit() const noexcept { return transit_; }  // node sent -> received
  const LatencyHistogram& trigger_leg() const noexcept { return trigger_leg_; }
  const LatencyHistogram& node_work() const noexcept { return node_work_; }
  // One line per node: messages, malformed, oversized, clock offset (report time). The
  // round-trip legs are in the run's statistics (LiveSetup::add_node_stats).
  std::string report() const;

 private:
  NodeLink() = default;
  // The mocap/blobs listener (Cyclone's receive thread; its calls never overlap).
  static void on_data(dds_entity_t reader, void* self) noexcept;
  void take_all(dds_entity_t reader) noexcept;
  void trigger_loop() noexcept;
  void on_sample(const mocap_node_BlobFrame& s) noexcept;
  void estimate_offset(NodeStats& n, const WireHeader& h, std::int64_t t3) noexcept;
  bool wait_for_nodes(double wait_s) noexcept;

  NodeDomain domain_;
  dds_entity_t reader_ = 0, writer_ = 0;
  double wait_s_ = 10.0;
  bool realtime_ = false;
  struct Camera {
    std::string node, camera;
    int node_index = 0;
  };
  std::vector<Camera> cameras_;
  std::vector<std::unique_ptr<NodeStats>> nodes_;
  std::vector<std::unique_ptr<rt::SlotPool<Received>>> inboxes_;
  std::vector<std::unique_ptr<rt::Counter>> full_;
  std::vector<std::int64_t> spare_;  // receiver: an acquired, unpublished slot or -1
  struct Posted {
    std::uint64_t number = 0;
    std::int64_t at_ns = 0;  // CLOCK_MONOTONIC, 0: on arrival
  };
  std::unique_ptr<rt::SpscRing<Posted>> triggers_;
  std::int64_t trigger_lead_ns_ = 0;
  // The trigger thread's fire_ns of trigger k at k % 256, for the receiver's node_work
  // (relaxed: a statistic; the echo arrives long after the write, 256 triggers never wrap
  // within a message's round trip).
  std::atomic<std::int64_t> fire_rt_[256] = {};
  std::uint64_t next_trigger_ = 0;  // capture thread: the lowest number not yet posted
  rt::Doorbell bell_, trigger_bell_;
  std::atomic<bool> stop_{false};
  std::atomic<std::uint64_t> received_end_{0};  // the receiver writes
  int users_ = 0;                               // started cameras (setup thread)
  rt::RtThread trigger_thread_;
  rt::Counter unknown_, triggers_sent_;
  LatencyHistogram transit_;
  LatencyHistogram trigger_leg_;  // central trigger written -> node received it
  LatencyHistogram node_work_;    // node received the trigger -> its message written
  std::string notice_;
};

}  // namespace mocap::node
