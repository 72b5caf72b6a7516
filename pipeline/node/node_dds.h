// Design: the DDS side shared by `mocap node` (node_sender.h) and the central tracker's
// node link (node_link.h): the participant on node.domain_id, the two topics and their
// QoS (docs/formats.md, "Camera nodes"), and the copy between a BlobFrame sample and
// the wire header (node_wire.h). Topics:
//   mocap/blobs    mocap_node::BlobFrame  node -> central, one message per camera frame
//   mocap/trigger  mocap_node::Trigger    central -> nodes, one per central trigger
// QoS of both: reliable (max blocking 100 ms), keep last 32, volatile: a lockstep replay
// loses no message on a healthy network, and a stalled peer can hold back at most 32.
// Real-time (`pipeline.realtime`, the default): the participant's domain is created with
// ONE Cyclone receive thread (`recv`; Internal/MultipleReceiveThreads false) at SCHED_FIFO
// kDdsFifoPriority, after the user's CYCLONEDDS_URI (which still applies otherwise), and
// the central's trigger writer (node_link.h) runs at the same priority: above the camera,
// capture and detection threads (80), so a message or trigger never waits for a
// detection to finish (default-policy threads waited milliseconds on a busy PC; docs/
// performance.md). The node's sender (node_sender.h) runs at kSenderFifoPriority, below
// its detection threads: it writes a pass's messages when a core is free of detection,
// never preempting one (above them it delayed the other node's detections on shared cores). Without
// the privilege Cyclone starts the thread with the default policy and the camera threads' notes say
// so. A domain this process already created (another NodeDomain, the ROS 2 output) is joined as it
// is. The node's domain batches its writes (NodeDomain::open, batch_writes): its sender flushes
// after the messages ready at once. Setup functions allocate and return one-line errors; the sample
// copies are noexcept.
#pragma once

#include <dds/dds.h>

#include <cstdint>
#include <string>

#include "core/expected.h"
#include "node_msgs.h"
#include "pipeline/node/node_wire.h"

namespace mocap::node {

inline constexpr const char* kBlobTopic = "mocap/blobs";
inline constexpr const char* kTriggerTopic = "mocap/trigger";
inline constexpr int kHistoryDepth = 32;
inline constexpr int kDdsFifoPriority = 85;     // Cyclone's receive thread and ours (realtime)
inline constexpr int kSenderFifoPriority = 75;  // the node's sender: below its detection (80)

// The participant and both topics; participant <= 0 when not open. Owns the participant
// (deleting it deletes every entity created under it) and, once its last participant is
// gone, the domain it created.
class NodeDomain {
 public:
  // batch_writes: the domain this process creates batches its writes (Cyclone's
  // Internal/WriteBatch): a write is sent at the writer's next dds_write_flush(), so the
  // messages written together leave in as few datagrams as fit (the node's sender).
  static Expected<NodeDomain> open(std::uint32_t domain_id, const std::string& who, bool realtime,
                                   bool batch_writes = false);
  NodeDomain() = default;
  NodeDomain(NodeDomain&& o) noexcept { *this = static_cast<NodeDomain&&>(o); }
  NodeDomain& operator=(NodeDomain&& o) noexcept;
  ~NodeDomain();

  dds_entity_t participant() const noexcept { return participant_; }
  dds_entity_t blob_topic() const noexcept { return blob_topic_; }
  dds_entity_t trigger_topic() const noexcept { return trigger_topic_; }
  // A reader or writer on a topic with the QoS above; one-line error naming `who`.
  Expected<dds_entity_t> writer(dds_entity_t topic, const std::string& who) const;
  Expected<dds_entity_t> reader(dds_entity_t topic, const std::string& who) const;

 private:
  void close() noexcept;
  dds_entity_t participant_ = 0, blob_topic_ = 0, trigger_topic_ = 0;
};

// Header fields sample <-> wire (names copied within their bound and NUL-terminated).
void to_sample(const WireHeader& h, mocap_node_BlobFrame& s) noexcept;
void from_sample(const mocap_node_BlobFrame& s, WireHeader& h) noexcept;

// CLOCK_REALTIME in ns (the clock PTP synchronises across PCs).
std::int64_t realtime_ns() noexcept;

}  // namespace mocap::node
