// Design: the replay's sensor. A loader thread reads one recording camera's frames, in
// the recording's order, into a fixed pool of Images ahead of their delivery, as a
// camera's DMA fills its buffers before the driver hands them out: dequeue() then only
// takes a loaded buffer, so the capture thread (which shares a core with half the
// detectors) never copies an image on the latency path.
//   Buffers move through two wait-free SPSC rings (rt/spsc_ring.h): `free` (capture
//   thread -> loader: give_back) and `loaded` (loader -> capture thread: next). A buffer
//   is in exactly one place: the free ring, the loader's hand, the loaded ring, or held
//   by the consumer between next() and give_back(). The rings' release/acquire order the
//   image bytes: the loader writes them before pushing, the consumer reads after popping;
//   the consumer has finished with a buffer before give_back() pushes it.
//   The loader sleeps on a doorbell (rt/doorbell.h: a futex with a timeout) when it has no
//   free buffer or nothing left to load; give_back(), skip_to() and the destructor ring it. It runs
//   with the default scheduling policy: the pipeline's SCHED_FIFO stages preempt it, so it reads
//   while they are idle.
// skip_to(index) makes the loader go on at frame `index` (never back) without reading
// the frames before it; entries it loaded before are still handed out (the consumer
// gives those back unused).
// Setup (start) allocates the images, rings and thread; next(), wait_next(), skip_to() and
// give_back() are noexcept and allocation-free (the capture thread's hot path); the
// loader's reads allocate nothing either (Recording::load_frame into a sized Image).
#pragma once

#include <atomic>
#include <cstdint>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "core/expected.h"
#include "core/image.h"
#include "formats/recording.h"
#include "rt/doorbell.h"
#include "rt/spsc_ring.h"

namespace mocap::hal {

enum class ReplayLoadStatus : std::uint8_t {
  kOk,
  kMissing,
  kError
};  // kError: malformed/wrong format

struct ReplayLoaded {  // a loaded buffer, handed from the loader to the consumer
  std::uint32_t buffer = 0;
  std::uint32_t frame_index = 0;  // into recording.frames()
  ReplayLoadStatus status = ReplayLoadStatus::kOk;
};

class ReplayReadAhead {
 public:
  using Status = ReplayLoadStatus;
  using Loaded = ReplayLoaded;

  // Starts loading frame 0 of camera `camera_index` into `buffers` images of `format`
  // (the rig's size). The thread is named `thread_name` (<= 15 characters).
  static Expected<std::unique_ptr<ReplayReadAhead>> start(std::shared_ptr<const Recording> rec,
                                                          int camera_index, int buffers,
                                                          PixelFormat format,
                                                          const std::string& thread_name);
  ~ReplayReadAhead();  // stops and joins the loader
  ReplayReadAhead(const ReplayReadAhead&) = delete;
  ReplayReadAhead& operator=(const ReplayReadAhead&) = delete;

  // Consumer (one thread). The next loaded frame, in order; false when it is not loaded
  // yet. wait_next() polls until deadline_ns (CLOCK_MONOTONIC; <= now: one try).
  bool next(Loaded& out) noexcept { return loaded_.try_pop(out); }
  bool wait_next(Loaded& out, std::int64_t deadline_ns) noexcept;
  const Image& image(std::uint32_t buffer) const noexcept { return images_[buffer]; }
  // The consumer is done with `buffer`: it may be loaded again.
  void give_back(std::uint32_t buffer) noexcept;
  // The loader's next frame is at least `index` (into recording.frames()).
  void skip_to(std::uint32_t index) noexcept;

 private:
  ReplayReadAhead(std::shared_ptr<const Recording> rec, int camera_index, std::vector<Image> images,
                  rt::SpscRing<std::uint32_t> free, rt::SpscRing<Loaded> loaded);
  void run() noexcept;
  void wake() noexcept;

  std::shared_ptr<const Recording> rec_;
  int camera_index_;
  std::vector<Image> images_;
  int width_, height_;  // the pool's shape (the rig's camera)
  PixelFormat format_;
  rt::SpscRing<std::uint32_t> free_;  // capture thread -> loader
  rt::SpscRing<Loaded> loaded_;       // loader -> capture thread
  rt::Doorbell wake_;
  std::atomic<std::uint32_t> skip_to_{0};  // consumer -> loader: the lowest frame to load
  std::atomic<bool> stop_{false};
  std::thread thread_;
};

}  // namespace mocap::hal
