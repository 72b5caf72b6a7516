// Design: the DDS side of `mocap node` (issue 29), between the node's camera threads
// (node_runner.h) and the network:
//   - the sender thread (`mocap-nsend`, SCHED_FIFO kSenderFifoPriority when realtime, below
//     the detection threads, so a write never preempts a detection in progress): takes
//     every camera's messages from its bounded drop-oldest queue (rt::DropOldestQueue<
//     WireFrame>, one per camera: one producer at a time; drops are counted and reported in
//     the camera's health), stamps sent_ns and writes them to mocap/blobs, every message
//     ready at its wake-up, then flushes them together (the node's domain batches writes:
//     a detection worker wakes the sender once per pass over its cameras, so a node's
//     messages of one trigger leave in one go). The camera and detection threads never
//     touch DDS (it locks and allocates).
//   - the mocap/trigger listener, called by Cyclone where it delivers a trigger (its
//     receive thread, real-time too: node_dds.h), so no thread hop: hands each trigger
//     (number, central send time, node receive time, the instant to fire at on this node's
//     CLOCK_MONOTONIC when the central scheduled it) to every camera with `trigger:
//     central` through its SPSC ring, then rings the detection workers' one doorbell
//     (after every camera's push), waking up to set_trigger_wakeups() of them.
// A scheduled trigger's instant (Trigger.fire_ns, the central's CLOCK_REALTIME) on this
// node's CLOCK_MONOTONIC, through this node's CLOCK_REALTIME (PTP keeps the two
// realtime clocks together): fire_instant(). One already past fires at once (late). The
// node never waits longer after the arrival than the central's lead (fire_ns - sent_ns,
// both on the central's clock; at most kMaxTriggerLeadUs): with the node's clock behind
// the central's by more than the trigger's way, the instant would lie further ahead, and
// it fires one lead after the arrival instead (unsynced: the exposures of the nodes then
// differ by the trigger's way, as without a lead).
// Setup allocates (queues of depth x 139 KiB per camera); the camera-thread side
// (queue push, trigger ring pop, doorbells) is noexcept, lock-free and allocation-free.
#pragma once

#include <atomic>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "core/camera_set.h"
#include "pipeline/node/node_dds.h"
#include "rt/counter.h"
#include "rt/doorbell.h"
#include "rt/drop_oldest_queue.h"
#include "rt/spsc_ring.h"
#include "rt/thread.h"

namespace mocap::node {

struct TriggerStamp {
  std::uint64_t number = 0;
  std::int64_t sent_ns = 0;      // central CLOCK_REALTIME
  std::int64_t received_ns = 0;  // node CLOCK_REALTIME
  std::int64_t fire_ns = 0;      // node CLOCK_MONOTONIC instant to fire at; 0: at once
};

struct FireInstant {
  std::int64_t mono_ns = 0;  // CLOCK_MONOTONIC to fire at; 0: at once
  bool late = false;         // scheduled, arrived after its instant
  bool unsynced = false;     // the instant lay further ahead than the lead: clocks apart
};
FireInstant fire_instant(std::int64_t fire_ns, std::int64_t sent_ns, std::int64_t now_rt,
                         std::int64_t now_mono) noexcept;

class NodeSender {
 public:
  // central[c]: camera c follows the central triggers. queue_depth: messages per camera.
  // realtime: Cyclone's receive thread (the trigger listener) at SCHED_FIFO
  // kDdsFifoPriority, the sender thread at kSenderFifoPriority.
  static Expected<std::unique_ptr<NodeSender>> create(std::uint32_t domain_id,
                                                      const std::vector<bool>& central,
                                                      int queue_depth, bool realtime);
  ~NodeSender();

  Expected<void> start();  // notes(): what of realtime was not applied
  const std::vector<std::string>& notes() const noexcept { return notes_; }
  // Stops both threads; first sends what is queued and waits (bounded) for the readers'
  // acknowledgements when `flush`.
  void stop(bool flush) noexcept;

  // Camera thread c (its producer ends).
  rt::DropOldestQueue<WireFrame>& queue(int c) noexcept { return *queues_[idx(c)]; }
  void wake() noexcept { bell_.ring(); }
  rt::SpscRing<TriggerStamp>& triggers(int c) noexcept { return *triggers_[idx(c)]; }
  // The detection workers' doorbell (node_runner.h): rung after each trigger's pushes.
  rt::Doorbell& trigger_bell() noexcept { return trigger_bell_; }
  // Setup, before start(): how many workers a trigger wakes (the workers sharing the bell).
  void set_trigger_wakeups(int workers) noexcept { trigger_wakeups_ = workers; }

  // Any thread.
  std::uint64_t sent() const noexcept { return sent_.get(); }
  std::uint64_t write_errors() const noexcept { return write_errors_.get(); }
  std::uint64_t triggers_received() const noexcept { return triggers_in_.get(); }
  std::uint64_t triggers_dropped() const noexcept { return triggers_dropped_.get(); }
  // Triggers whose instant lay further ahead than their lead (clocks apart): fired one
  // lead after the arrival.
  std::uint64_t triggers_unsynced() const noexcept { return triggers_unsynced_.get(); }
  // Scheduled triggers that arrived after their instant (the lead was shorter than the
  // trigger's way): fired on arrival.
  std::uint64_t triggers_late() const noexcept { return triggers_late_.get(); }
  // Matched central readers of mocap/blobs (0 when unknown).
  std::uint32_t matched_readers() const noexcept;

 private:
  NodeSender() = default;
  static std::size_t idx(int c) noexcept { return static_cast<std::size_t>(c); }
  void send_loop() noexcept;
  bool send_pending() noexcept;  // true when something was written
  // The mocap/trigger listener (Cyclone's receive thread; its calls never overlap).
  static void on_triggers(dds_entity_t reader, void* self) noexcept;
  void take_triggers(dds_entity_t reader) noexcept;

  NodeDomain domain_;
  dds_entity_t writer_ = 0, trigger_reader_ = 0;
  std::vector<bool> central_;
  bool realtime_ = false;
  std::vector<std::string> notes_;
  std::vector<std::unique_ptr<rt::DropOldestQueue<WireFrame>>> queues_;
  std::vector<std::unique_ptr<rt::SpscRing<TriggerStamp>>> triggers_;
  rt::Doorbell trigger_bell_;
  int trigger_wakeups_ = 1;
  rt::Doorbell bell_;
  std::atomic<bool> stop_{false};
  rt::RtThread send_thread_;
  rt::Counter sent_, write_errors_, triggers_in_, triggers_dropped_, triggers_unsynced_,
      triggers_late_;
};

}  // namespace mocap::node
