// Design: the `node` camera backend of the central tracker (`{backend: node, device:
// NODE/CAMERA}`; docs/hal.md, "Camera nodes"): camera CAMERA of `mocap node` NODE, whose
// frames arrive as blob lists over DDS (NodeLink's inbox) instead of images. A Frame it
// delivers carries `blobs` (the detect stage passes them through, no detection) and no
// image; release() gives the inbox slot back.
// Trigger modes:
//   kSoftware (default): the central tracker triggers; trigger() posts central trigger k
//     (the camera's k-th trigger, the same k for every node camera) to the nodes, whose
//     `trigger: central` cameras answer with frame number k; trigger_at(t) posts it
//     node.trigger_lead_us ahead of its instant t, at which the nodes fire (the frame's
//     latency starts at t, or at trigger()'s call). dequeue() delivers frame k in
//     order, and survives the node: a frame not arrived `timeout_ms` after its trigger is
//     delivered as MISSING (the set goes on with the other cameras); after 3 missing in a
//     row the camera is down and its frames are missing at once, until a message of it
//     arrives again (counted in node_reconnects). A frame is only declared missing once
//     another node answered its trigger (NodeLink::received_end): when every node is
//     silent nothing is invented, and a replay's end (answered by end-of-stream messages)
//     ends the run instead of becoming a frame of missing cameras. A message older than the next
//     frame is late, one already delivered a duplicate: counted and dropped.
//   kExternal / kFreeRun: the node triggers (hardware line, or free-running): frames are
//     delivered as they arrive (numbers must increase; older ones are late/duplicates,
//     unless captured after the last frame delivered: a restarted node, whose numbers
//     start over, counted in node_reconnects). Nothing is declared missing here: a silent
//     node's cameras are left out of the frame sets by the identify stage's pairer after
//     a bound (PipelineOptions::silent_after_ns: node.timeout_ms plus a frame period).
// The node's end of stream (its replay ended) is this camera's kEndOfStream.
// Capture times: a replay's stay the recording's; a live camera's (node CLOCK_MONOTONIC)
// are mapped onto this host's CLOCK_MONOTONIC through CLOCK_REALTIME (both hosts'
// realtime - monotonic offsets; PTP keeps the realtime clocks together), so that
// `pair_by: timestamp` compares the nodes' frames on one clock.
// Hot-path calls are noexcept, lock-free and allocation-free (capture thread only).
#pragma once

#include <cstdint>
#include <memory>
#include <string>

#include "hal/camera_base.h"
#include "pipeline/node/node_link.h"

namespace mocap::node {

class NodeCamera final : public hal::CameraBase {
 public:
  // device: "NODE/CAMERA". slots: inbox messages; max_blobs: the central detector's bound.
  static Expected<std::unique_ptr<NodeCamera>> open(std::shared_ptr<NodeLink> link,
                                                    const std::string& device, int max_blobs,
                                                    int timeout_ms);
  ~NodeCamera() override;
  Expected<void> configure(const hal::CameraConfig& config) override;
  Expected<void> start() override;
  void stop() noexcept override;
  hal::CameraStatus trigger() noexcept override;
  // node.trigger_lead_us (kSoftware): the nodes fire at the instant trigger_at() names.
  std::int64_t trigger_lead_ns() const noexcept override;
  hal::CameraStatus trigger_at(std::int64_t at_ns) noexcept override;
  bool delivers_blobs() const noexcept override { return true; }
  hal::CameraStatus dequeue(hal::Frame& out, int timeout_ms) noexcept override;
  hal::CameraStatus release(const hal::Frame& frame) noexcept override;

  hal::CameraConfig native_config() const;
  std::uint64_t late() const noexcept { return late_.get(); }
  std::uint64_t duplicates() const noexcept { return duplicates_.get(); }
  std::uint64_t reconnects() const noexcept { return reconnects_.get(); }
  std::uint64_t inbox_full() const noexcept { return link_->inbox_full(index_); }

 private:
  NodeCamera(std::shared_ptr<NodeLink> link, int index, std::string device, int timeout_ms);
  static constexpr std::uint32_t kNoSlot = 0xffffffffu;
  static constexpr std::size_t kWindow = 256;  // trigger times / delivered marks kept
  // Posts the next central trigger: its latencies start at instant_ns, the nodes fire at
  // fire_ns (0: on arrival).
  hal::CameraStatus post(std::int64_t instant_ns, std::int64_t fire_ns) noexcept;
  // Takes the next message of the inbox into held_ (true) or nothing is there.
  bool take() noexcept;
  void deliver_held(hal::Frame& out) noexcept;
  void deliver_missing(hal::Frame& out) noexcept;
  // A message's capture time on this host's CLOCK_MONOTONIC (a replay's: the recording's).
  static std::int64_t mapped_capture_ns(const WireHeader& h) noexcept;

  std::shared_ptr<NodeLink> link_;
  const int index_;
  const std::int64_t timeout_ns_;
  bool central_ = true;  // kSoftware
  bool eos_ = false;     // the node's end-of-stream message arrived
  bool down_ = false;
  int missing_run_ = 0;
  std::uint64_t triggered_ = 0;                 // central triggers posted
  std::uint64_t next_ = 0;                      // next frame number to deliver (central mode)
  std::int64_t trigger_ns_[kWindow] = {};       // CLOCK_MONOTONIC of trigger k % kWindow
  std::uint64_t delivered_real_[kWindow] = {};  // k + 1 when frame k was delivered real
  bool have_last_ = false;
  std::uint64_t last_number_ = 0;  // last real frame number delivered
  std::int64_t last_capture_ns_ = 0, period_ns_ = 0;
  std::int64_t last_mapped_ns_ = 0;  // mapped_capture_ns of the last real frame delivered
  bool held_valid_ = false;
  rt::SlotHandle held_ = 0;
  rt::Counter late_, duplicates_, reconnects_;
};

}  // namespace mocap::node
