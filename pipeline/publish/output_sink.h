// Design: the output seam. Every output of the live tracker (UDP, iceoryx, ROS 2 over
// DDS, the Foxglove live view, ...) is an OutputSink built at setup from the run
// configuration's `outputs:` list and the CLI flags through one registry, and called by
// the publish stage once per frame with the frame's whole result (frame_result.h).
// publish() runs on the real-time publish thread: noexcept, no allocation, no locks, no
// blocking; a false return is counted by the caller and never stops the pipeline. A
// slow encoder (JSON, DDS, disk) does not encode in publish(): it copies the result into
// a bounded drop-oldest queue drained by its own non-real-time thread, and counts drops.
// Names of bodies, markers and joints reach the sinks once, at setup (OutputContext).
#pragma once

#include <cstdint>
#include <string>

#include "camera/camera_model.h"
#include "formats/joints_yaml.h"
#include "formats/targets_yaml.h"
#include "pipeline/publish/frame_result.h"

namespace mocap::publish {

// What a sink may need to know at setup. The pointers live only during the sink's
// create(): a sink copies what it keeps (names, joint centres and axes).
struct OutputContext {
  const TargetSet* targets = nullptr;  // body and marker order of FrameResult
  const JointModel* model = nullptr;   // joint order of FrameResult::joints; may be null
  const Rig* rig = nullptr;            // camera order of FrameResult::cameras; may be null
  double frame_rate_hz = 0.0;          // trigger rate, 0 if unknown
};

// Counters every sink reports (read from other threads: relaxed snapshots).
struct OutputCounters {
  std::uint64_t published = 0;      // frames handed over to the transport / encoder
  std::uint64_t failures = 0;       // frames the transport refused
  std::uint64_t dropped = 0;        // frames dropped by a bounded queue (drop-oldest)
  std::uint64_t no_listener = 0;    // frames sent while a destination reported no listener
                                    // (UDP: ICMP port unreachable); not failures
  std::uint64_t not_predicted = 0;  // lead_ms outputs: frames sent as measured, their capture
                                    // too old to predict to publish + lead (lead.h)
};

class OutputSink {
 public:
  OutputSink() = default;
  OutputSink(const OutputSink&) = delete;
  OutputSink& operator=(const OutputSink&) = delete;
  virtual ~OutputSink() = default;

  // Short name for statistics and messages ("udp", "iceoryx", "ros2", "foxglove").
  virtual const char* name() const noexcept = 0;
  // Publish thread only. False: not delivered (counted by the caller).
  virtual bool publish(const FrameResult& frame) noexcept = 0;
  // Counter snapshot (any thread).
  virtual OutputCounters counters() const noexcept = 0;
  // One line to print once at start (for example a missing daemon), or empty.
  virtual std::string notice() const { return {}; }
};

}  // namespace mocap::publish
