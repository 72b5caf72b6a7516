// Design: where the pipeline's output goes. The publish stage calls publish() once per
// frame that reached the end of the pipeline, on the publish thread (noexcept, no
// allocation, no locks: UDP sendto, an iceoryx loan+publish). A false return is counted
// (sink_failures) and never stops the pipeline. Sinks are owned by the caller and must
// outlive the running pipeline. make_joints_message() builds the public message from a
// processed frame (allocation-free).
#pragma once

#include <cstdint>

#include "client/joints_message.h"
#include "track/frame_processor.h"

namespace mocap::pipeline {

class JointsSink {
 public:
  virtual ~JointsSink() = default;
  JointsSink() = default;
  JointsSink(const JointsSink&) = delete;
  JointsSink& operator=(const JointsSink&) = delete;
  // Publish thread only. False: this message was not delivered (counted).
  virtual bool publish(const client::JointsMessage& message) noexcept = 0;
};

// Fills `msg` from the frame's joint angles (sequence, capture_ns, flags, joints);
// publish_ns is set by the publish stage.
void make_joints_message(std::uint64_t sequence, std::int64_t capture_ns, const FrameOutput& out,
                         client::JointsMessage& msg) noexcept;

}  // namespace mocap::pipeline
