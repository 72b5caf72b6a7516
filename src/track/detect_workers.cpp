// Design: see detect_workers.h.
#include "track/detect_workers.h"

#include "core/clock.h"

namespace mocap {

ParallelDetect::ParallelDetect(FrameProcessor& proc) : proc_(proc) {
  worker_ = std::thread([this] { run(); });
}

ParallelDetect::~ParallelDetect() {
  // release: the worker that sees stop_ (acquire) stops; the increment wakes it.
  stop_.store(true, std::memory_order_release);
  posted_.fetch_add(1, std::memory_order_release);
  posted_.notify_one();
  worker_.join();
}

void ParallelDetect::detect_share(int first_camera) noexcept {
  for (int c = first_camera; c < proc_.camera_count(); c += 2) {
    const auto uc = static_cast<std::size_t>(c);
    const ImageView* view = uc < views_.size() ? views_[uc] : nullptr;
    out_->blobs[uc].clear();
    out_->camera_present[uc] = view != nullptr;
    if (view != nullptr) proc_.detect_camera(c, *view, out_->blobs[uc]);
  }
}

void ParallelDetect::run() noexcept {
  std::uint32_t seen = 0;
  for (;;) {
    // acquire: pairs with the caller's release increment, so views_ and out_ (and
    // stop_) written before it are visible here.
    posted_.wait(seen, std::memory_order_acquire);
    seen = posted_.load(std::memory_order_acquire);
    if (stop_.load(std::memory_order_acquire)) return;
    detect_share(1);
    // release: the caller's acquire load of done_ sees the odd cameras' blob lists.
    done_.store(seen, std::memory_order_release);
    done_.notify_one();
  }
}

void ParallelDetect::detect(std::span<const ImageView* const> views, FrameOutput& out) noexcept {
  const std::int64_t t0 = monotonic_ns();
  views_ = views;
  out_ = &out;
  // release: publishes views_ and out_ to the worker (see run()).
  const std::uint32_t frame = posted_.fetch_add(1, std::memory_order_release) + 1;
  posted_.notify_one();
  detect_share(0);
  // acquire: pairs with the worker's release store; its blob lists are complete.
  for (std::uint32_t d = done_.load(std::memory_order_acquire); d != frame;
       d = done_.load(std::memory_order_acquire))
    done_.wait(d, std::memory_order_acquire);
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
