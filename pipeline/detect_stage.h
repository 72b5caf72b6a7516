// Design: the detect stage of one camera (one thread per camera of the rig, placed by
// the stage table's detect rule). It owns its input: the ring of camera frames the
// capture hands it (sized by the stage table's ring depth) and the ring that gives every
// frame back to the capture right after detection (sized by the camera's buffer count,
// so it never fills). It fills blob slots of the identify stage's pool for its camera.
//   input ring --newest frame--> FrameProcessor::detect_camera --> blob slot (identify)
//        ^-- older frames (skipped) and the detected frame go back on the return ring
// A camera node's frame (hal::Frame::blobs, pipeline/node/node_camera.h) carries the blobs
// its node detected and no image: they are copied into the blob slot, not detected. Such a
// camera's stage (hal::Camera::delivers_blobs) has no thread: the capture thread hands each
// frame through pass() (the one producer of its blob slots, the only writer of its
// counters), which saves a thread's wake-up between the blobs' arrival and identify.
// Either way pass() undistorts the slot's blobs for identify (FrameProcessor::
// undistort_camera), on this camera's detect thread or on the capture thread.
// Drop policy: it works on the NEWEST frame and returns the older ones (detect#_skipped);
// when identify holds every blob slot the frame is dropped (detect#_no_slot). With
// options.every_frame (`mocap record --blobs`, `pipeline.every_frame`) it detects every frame in
// order (no skips; a full input ring drops at the capture). options.blob_tap, if set, gets each
// detected frame's blob list on this thread (BlobTap, pipeline_options.h).
// Its counters, the detector library's mirrored counters (detect_cam#_*) and its two
// histograms (latency from the trigger, own work) have this thread as only writer.
// run() is the hot path: noexcept, allocation-free, lock-free, no logging.
#pragma once

#include <cstdint>
#include <memory>

#include "core/expected.h"
#include "core/latency_histogram.h"
#include "hal/camera.h"
#include "pipeline/stage_context.h"
#include "pipeline/stage_counters.h"
#include "rt/counter_group.h"
#include "rt/slot_pool.h"
#include "rt/spsc_ring.h"
#include "track/frame_processor.h"

namespace mocap::pipeline {

class DetectStage {
 public:
  // input_depth: the stage table's ring depth; `cam` (configured) sizes the return ring.
  static Expected<std::unique_ptr<DetectStage>> create(int camera, const hal::Camera& cam,
                                                       std::uint32_t input_depth,
                                                       StageContext& context,
                                                       FrameProcessor& processor,
                                                       rt::SlotPool<BlobSlot>& out);

  void run() noexcept;  // the thread's body, until the context stops
  // The camera delivers blobs (no detection): no thread; the capture thread calls pass()
  // for each frame and releases the frame itself afterwards.
  bool passes_through() const noexcept { return passes_through_; }
  // The frame's blobs (detected, or passed on) into a blob slot for identify; dropped and
  // counted (detect#_no_slot) when identify holds every slot. run() calls it too.
  void pass(const hal::Frame& f) noexcept;

  // The capture thread's ends: push frames in, take frames back.
  rt::SpscRing<hal::Frame>& input() noexcept { return input_; }
  rt::SpscRing<hal::Frame>& returned() noexcept { return returned_; }

  int camera() const noexcept { return camera_; }
  // Any thread.
  const LatencyHistogram& latency() const noexcept { return latency_; }  // from the trigger
  const LatencyHistogram& work() const noexcept { return work_; }
  std::uint64_t overflow_frames() const noexcept {
    return library_.detector.get(kDetectorFramesOverflow);
  }
  void report(rt::CounterReport& out) const;  // report time

 private:
  DetectStage(int camera, std::uint32_t input_capacity, std::uint32_t return_capacity,
              StageContext& context, FrameProcessor& processor, rt::SlotPool<BlobSlot>& out,
              bool passes_through);

  const int camera_;
  const bool passes_through_;
  StageContext& context_;
  FrameProcessor& processor_;
  rt::SlotPool<BlobSlot>& out_;
  rt::SpscRing<hal::Frame> input_;
  rt::SpscRing<hal::Frame> returned_;

  struct alignas(64) Counters {
    explicit Counters(int camera) noexcept : group(camera) {}
    rt::CounterGroup group;
    rt::NamedCounter skipped{group, "detect#_skipped"};  // older frames not detected
    rt::NamedCounter no_slot{group, "detect#_no_slot"};  // identify held every blob slot
  } counters_;
  struct alignas(64) Library {
    DetectorMirror detector;  // reported as detect_cam#_<field>
    rt::Counter blobs;        // blobs handed to identify (detect_cam#_blobs)
  } library_;
  LatencyHistogram latency_;
  LatencyHistogram work_;
};

}  // namespace mocap::pipeline
