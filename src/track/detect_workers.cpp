// Design: see detect_workers.h.
#include "track/detect_workers.h"

#include "core/clock.h"
#include "rt/cpu_relax.h"

namespace mocap {

ParallelDetect::ParallelDetect(FrameProcessor& proc) : proc_(proc) {
  worker_ = std::thread([this] { run(); });
}

ParallelDetect::~ParallelDetect() {
  // release: the worker that sees stop_ (acquire) stops; the ring wakes it.
  stop_.store(true, std::memory_order_release);
  posted_.ring();
  worker_.join();
}

void ParallelDetect::detect_claimed(std::uint32_t gen) noexcept {
  const auto n = static_cast<std::uint32_t>(proc_.camera_count());
  std::uint64_t v = next_.load(std::memory_order_relaxed);
  for (;;) {
    if (static_cast<std::uint32_t>(v >> 32) != gen || static_cast<std::uint32_t>(v) >= n) return;
    // acquire on success: pairs with the caller's release store of this generation, so
    // views_ and out_ are this frame's; relaxed on failure (v is reloaded and re-checked).
    if (!next_.compare_exchange_weak(v, v + 1, std::memory_order_acquire,
                                     std::memory_order_relaxed))
      continue;
    const auto uc = static_cast<std::size_t>(static_cast<std::uint32_t>(v));
    const ImageView* view = uc < views_.size() ? views_[uc] : nullptr;
    out_->blobs[uc].clear();
    out_->camera_present[uc] = view != nullptr;
    if (view != nullptr) {
      proc_.detect_camera(static_cast<int>(uc), *view, out_->blobs[uc]);
      // Stage 2's first step too, on this thread (FrameProcessor::undistort_camera).
      if (uc < out_->undistorted.size())
        proc_.undistort_camera(static_cast<int>(uc), out_->blobs[uc], out_->undistorted[uc]);
    }
    // release: the caller's acquire load of completed_ sees this camera's blob list.
    if (completed_.fetch_add(1, std::memory_order_release) + 1 == n) done_.ring();
    v = next_.load(std::memory_order_relaxed);
  }
}

void ParallelDetect::run() noexcept {
  std::uint32_t seen = 0;
  std::uint32_t taken = 0;  // the last generation whose cameras this thread claimed
  for (;;) {
    // Asleep until a ring after `seen` (a frame, warm() or the destructor) or the timeout;
    // the frame itself is published through next_ (detect_claimed).
    posted_.wait(seen, kWaitNs);
    const std::uint32_t now = posted_.snapshot();
    if (now == seen) {  // the timeout, not a ring: nothing to spin for
      // acquire: pairs with the destructor's release store.
      if (stop_.load(std::memory_order_acquire)) return;
      continue;
    }
    seen = now;
    // Rung for a frame or by warm(): spin until a new generation is posted (bounded).
    const std::int64_t t0 = monotonic_ns();
    for (;;) {
      if (stop_.load(std::memory_order_acquire)) return;
      // acquire: pairs with the caller's release store of the generation, so the bell the
      // caller rang before it (detect()) is in the load of posted_ below.
      const auto gen = static_cast<std::uint32_t>(next_.load(std::memory_order_acquire) >> 32);
      if (gen != taken) {
        taken = gen;
        // This frame's bell is consumed: sleep until the next warm() or frame, instead of
        // spinning through the frame's other stages.
        seen = posted_.snapshot();
        detect_claimed(gen);
        break;
      }
      if (monotonic_ns() - t0 > kWarmSpinNs) break;
      rt::cpu_relax();
    }
  }
}

void ParallelDetect::warm() noexcept { posted_.ring(); }

void ParallelDetect::detect(std::span<const ImageView* const> views, FrameOutput& out) noexcept {
  const std::int64_t t0 = monotonic_ns();
  const auto n = static_cast<std::uint32_t>(proc_.camera_count());
  // Every claim of the previous frame completed before it returned: nothing reads these.
  views_ = views;
  out_ = &out;
  completed_.store(0, std::memory_order_relaxed);
  const std::uint32_t gen = ++generation_;
  // The bell before the frame: a worker that sees the generation (acquire) also sees the
  // ring (seq_cst), so it does not wake again for this frame.
  posted_.ring();
  // release: publishes views_, out_ and the reset count with the generation's counter.
  next_.store(static_cast<std::uint64_t>(gen) << 32, std::memory_order_release);
  detect_claimed(gen);
  // acquire: pairs with each claim's release increment; every blob list is complete.
  // The worker's last camera is short: spin for it first, then sleep.
  const std::int64_t t_spin = monotonic_ns();
  std::uint32_t k = completed_.load(std::memory_order_acquire);
  while (k != n && monotonic_ns() - t_spin < kFinishSpinNs) {
    rt::cpu_relax();
    k = completed_.load(std::memory_order_acquire);
  }
  while (k != n) {
    // The snapshot before the look: a ring between them is not lost (rt::Doorbell).
    const std::uint32_t seen = done_.snapshot();
    k = completed_.load(std::memory_order_acquire);
    if (k != n) done_.wait(seen, kWaitNs);
  }
  out.times.detect = monotonic_ns() - t0;
}

bool ParallelDetect::process(std::span<const ImageView* const> views, std::int64_t timestamp_ns,
                             FrameOutput& out) noexcept {
  const std::int64_t t0 = monotonic_ns();
  detect(views, out);
  const bool ok = proc_.process_blobs(timestamp_ns, out);
  out.times.frame = monotonic_ns() - t0;
  return ok;
}

}  // namespace mocap
