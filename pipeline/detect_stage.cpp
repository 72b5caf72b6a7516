// Design: see detect_stage.h.
#include "pipeline/detect_stage.h"

#include <string>

namespace mocap::pipeline {

Expected<std::unique_ptr<DetectStage>> DetectStage::create(int camera, const hal::Camera& cam,
                                                           std::uint32_t input_depth,
                                                           StageContext& context,
                                                           FrameProcessor& processor,
                                                           rt::SlotPool<BlobSlot>& out) {
  if (camera < 0 || camera >= kMaxCameras)
    return make_error("pipeline", "camera", "index " + std::to_string(camera) + " out of range");
  // Camera buffers: the input ring, one in the detector's hand, one on its way back.
  const int camera_buffers = cam.config().buffer_count;
  if (camera_buffers < static_cast<int>(input_depth) + 2) {
    return make_error(cam.name(), "buffer_count",
                      std::to_string(camera_buffers) +
                          " buffers; the pipeline needs detect ring_depth + 2 = " +
                          std::to_string(input_depth + 2));
  }
  const auto input = static_cast<std::uint32_t>(rt::next_power_of_two_at_least(input_depth));
  const auto back = static_cast<std::uint32_t>(
      rt::next_power_of_two_at_least(static_cast<std::size_t>(camera_buffers)));
  return std::unique_ptr<DetectStage>(
      new DetectStage(camera, input, back, context, processor, out, cam.delivers_blobs()));
}

DetectStage::DetectStage(int camera, std::uint32_t input_capacity, std::uint32_t return_capacity,
                         StageContext& context, FrameProcessor& processor,
                         rt::SlotPool<BlobSlot>& out, bool passes_through)
    : camera_(camera),
      passes_through_(passes_through),
      context_(context),
      processor_(processor),
      out_(out),
      input_(input_capacity),
      returned_(return_capacity),
      counters_(camera) {}

void DetectStage::run() noexcept {
  const StageId id = StageId::detect(camera_);
  context_.loop_start(id);
  rt::Doorbell& bell = context_.bell(id);
  const PipelineOptions& options = context_.options();
  while (!context_.stopping()) {
    const std::uint32_t seen = bell.snapshot();
    hal::Frame f;
    if (!input_.try_pop(f)) {
      bell.wait(seen, kIdleWaitNs);
      continue;
    }
    // Catch-up: the oldest frame while it is fresh, else the next (options.fresh).
    const std::int64_t now = monotonic_ns();
    hal::Frame newer;
    while (!options.fresh(hal::latency_origin_ns(f), now) && input_.try_pop(newer)) {
      returned_.try_push(f);  // cannot fail: holds every camera buffer
      counters_.skipped.add();
      context_.note_detected(camera_);
      f = newer;
    }
    pass(f);
    returned_.try_push(f);            // the image is no longer needed
    context_.note_detected(camera_);  // after pass(): its blob slot is in identify's pool
  }
  context_.loop_end(id);
}

void DetectStage::pass(const hal::Frame& f) noexcept {
  rt::SlotHandle h;
  if (!out_.acquire(h)) {  // identify holds every slot (stalled): drop
    counters_.no_slot.add();
    return;
  }
  const std::int64_t t0 = monotonic_ns();
  BlobSlot& slot = out_[h];
  slot.blobs.clear();
  slot.undistorted.received = -1;
  slot.present = !f.missing && (!f.image.empty() || f.blobs != nullptr);
  if (slot.present && f.blobs != nullptr) {  // a camera node detected them: pass through
    for (const detect::Blob& b : *f.blobs) slot.blobs.push_back(b);  // capacity: counted
    slot.blobs.set_levels(f.blobs->levels());
  } else if (slot.present) {
    processor_.detect_camera(camera_, f.image, slot.blobs);
    library_.detector.publish(kDetectorFields, processor_.detector_counters(camera_));
  }
  if (slot.present) {
    // Stage 2's first step here, off the identify stage (FrameProcessor::undistort_camera):
    // on this camera's detect thread, in parallel with the other cameras'; for a camera
    // node's blobs on the capture thread (a few us per camera), while it waits for the
    // set's other cameras.
    processor_.undistort_camera(camera_, slot.blobs, slot.undistorted);
    library_.blobs.add(slot.blobs.size());
  }
  if (BlobTap* const tap = context_.options().blob_tap; tap != nullptr)
    tap->on_blobs(camera_, f, slot.present, slot.blobs);
  slot.sequence = f.sequence;
  slot.capture_ns = f.timestamp_ns;
  const std::int64_t origin_ns = hal::latency_origin_ns(f);
  slot.origin_ns = origin_ns;  // (a local copy: the slot is identify's once published)
  out_.publish(h);
  context_.bell(StageId::kIdentify).ring();
  const std::int64_t t1 = monotonic_ns();
  work_.record(t1 - t0);
  latency_.record(t1 - origin_ns);
}

void DetectStage::report(rt::CounterReport& out) const {
  counters_.group.report(0, out);
  const std::string prefix = rt::counter_name("detect_cam#_", camera_);
  out.emplace_back(prefix + "blobs", library_.blobs.get());
  for (std::size_t i = 0; i < kDetectorFields.size(); ++i)
    out.emplace_back(prefix + kDetectorFields[i].name, library_.detector.get(i));
}

}  // namespace mocap::pipeline
