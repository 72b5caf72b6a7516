// Design: see frame_source.h.
#include "track/frame_source.h"

#include "core/clock.h"

namespace mocap {

FrameSource::FrameSource(const Recording& rec, FrameProcessor& proc, int detect_threads)
    : rec_(rec), proc_(proc) {
  if (rec.has_blobs()) {
    scratch_.resize(rec.rig().cameras.size());
    return;
  }
  images_.emplace(rec);
  if (detect_threads >= 2 && proc.camera_count() >= 2) parallel_.emplace(proc);
}

FrameSource::Result FrameSource::load(std::int64_t frame, FrameOutput& out) {
  Result r;
  const int n = proc_.camera_count();
  const std::int64_t t_read = monotonic_ns();
  if (!rec_.has_blobs()) {
    if (parallel_) parallel_->warm();  // its wake-up overlaps the reading
    const FrameSetLoader::Result loaded = images_->load(frame);
    out.times.load = monotonic_ns() - t_read;
    r.missing = loaded.missing;
    r.damaged = loaded.damaged;
    r.problem = loaded.problem;
    r.present = n - r.missing - r.damaged;
    if (parallel_) {
      parallel_->detect(images_->views(), out);
      return r;
    }
    const std::int64_t t0 = monotonic_ns();
    const auto views = images_->views();
    for (int c = 0; c < n; ++c) {
      const auto uc = static_cast<std::size_t>(c);
      const ImageView* view = uc < views.size() ? views[uc] : nullptr;
      out.blobs[uc].clear();
      out.camera_present[uc] = view != nullptr;
      if (view != nullptr) proc_.detect_camera(c, *view, out.blobs[uc]);
    }
    out.times.detect = monotonic_ns() - t0;
    return r;
  }
  for (int c = 0; c < n; ++c) {
    const auto uc = static_cast<std::size_t>(c);
    out.camera_present[uc] = false;
    auto loaded = rec_.load_blobs(c, frame, out.blobs[uc], scratch_[uc]);
    if (!loaded) {
      out.blobs[uc].clear();
      if (r.damaged++ == 0) r.problem = loaded.error().message;
    } else if (*loaded == FrameLoad::kMissing) {
      ++r.missing;
    } else {
      out.camera_present[uc] = true;
      ++r.present;
    }
  }
  out.times.load = monotonic_ns() - t_read;
  out.times.detect = 0;  // nothing to detect: the recording holds the blob lists
  return r;
}

FrameSource::Result FrameSource::process(const FrameEntry& entry, FrameOutput& out) {
  Result r = load(entry.frame, out);
  const std::int64_t t0 = monotonic_ns();
  proc_.process_blobs(entry.timestamp_ns, out);
  // The in-memory work (the spec's `frame`): detection and the stages after it, without
  // the file reading (times.load).
  out.times.frame = out.times.detect + (monotonic_ns() - t0);
  return r;
}

}  // namespace mocap
