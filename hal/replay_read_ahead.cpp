// Design: see replay_read_ahead.h.
#include "hal/replay_read_ahead.h"

#include <pthread.h>

#include <algorithm>
#include <utility>

#include "core/clock.h"

namespace mocap::hal {
namespace {

// How often a consumer that caught up with the loader looks again (only when the
// loader is behind: a replay faster than the disk).
constexpr std::int64_t kReadAheadPollNs = 50'000;
// The loader's sleep's safety net (a ring wakes it at once).
constexpr std::int64_t kLoaderWaitNs = 100'000'000;

}  // namespace

Expected<std::unique_ptr<ReplayReadAhead>> ReplayReadAhead::start(
    std::shared_ptr<const Recording> rec, int camera_index, int buffers, PixelFormat format,
    const std::string& thread_name) {
  if (!rec || camera_index < 0 ||
      static_cast<std::size_t>(camera_index) >= rec->rig().cameras.size())
    return make_error("replay", "camera", "no such camera in the recording");
  if (buffers < 1) return make_error(rec->dir(), "buffer_count", "must be positive");
  if (thread_name.empty() || thread_name.size() > 15)
    return make_error(rec->dir(), "thread", "name must have 1..15 characters");
  const CameraModel& cam = rec->rig().cameras[static_cast<std::size_t>(camera_index)];
  std::vector<Image> images(static_cast<std::size_t>(buffers));
  for (Image& im : images)
    im.allocate(cam.width, cam.height, format,
                static_cast<std::uint16_t>(format == PixelFormat::kMono8 ? 255 : 65535));
  const auto capacity = rt::next_power_of_two_at_least(static_cast<std::size_t>(buffers));
  auto free = rt::SpscRing<std::uint32_t>::create(capacity);
  if (!free) return free.error();
  auto loaded = rt::SpscRing<Loaded>::create(capacity);
  if (!loaded) return loaded.error();
  for (int b = 0; b < buffers; ++b) free->try_push(static_cast<std::uint32_t>(b));
  std::unique_ptr<ReplayReadAhead> ra(new ReplayReadAhead(
      std::move(rec), camera_index, std::move(images), std::move(*free), std::move(*loaded)));
  ReplayReadAhead* self = ra.get();
  ra->thread_ = std::thread([self] { self->run(); });
  pthread_setname_np(ra->thread_.native_handle(), thread_name.c_str());  // cosmetic
  return ra;
}

ReplayReadAhead::ReplayReadAhead(std::shared_ptr<const Recording> rec, int camera_index,
                                 std::vector<Image> images, rt::SpscRing<std::uint32_t> free,
                                 rt::SpscRing<Loaded> loaded)
    : rec_(std::move(rec)),
      camera_index_(camera_index),
      images_(std::move(images)),
      width_(images_.front().width()),
      height_(images_.front().height()),
      format_(images_.front().format()),
      free_(std::move(free)),
      loaded_(std::move(loaded)) {}

ReplayReadAhead::~ReplayReadAhead() {
  // relaxed: the wake() below orders it (the loader re-reads stop_ after each wake).
  stop_.store(true, std::memory_order_relaxed);
  wake();
  if (thread_.joinable()) thread_.join();
}

void ReplayReadAhead::wake() noexcept {
  // The ring (seq_cst) makes what the waker did before (a buffer pushed, stop_) visible
  // to the loader whose snapshot sees it.
  wake_.ring();
}

void ReplayReadAhead::give_back(std::uint32_t buffer) noexcept {
  free_.try_push(buffer);  // never full: the ring holds every buffer
  wake();
}

void ReplayReadAhead::skip_to(std::uint32_t index) noexcept {
  skip_to_.store(index, std::memory_order_relaxed);  // wake()'s release publishes it
  wake();
}

bool ReplayReadAhead::wait_next(Loaded& out, std::int64_t deadline_ns) noexcept {
  for (;;) {
    if (loaded_.try_pop(out)) return true;
    const std::int64_t now = monotonic_ns();
    if (now >= deadline_ns) return false;
    sleep_until_ns(std::min(deadline_ns, now + kReadAheadPollNs));
  }
}

void ReplayReadAhead::run() noexcept {
  const std::vector<FrameEntry>& frames = rec_->frames();
  std::size_t next = 0;
  std::uint32_t buffer = 0;
  bool have_buffer = false;
  while (!stop_.load(std::memory_order_relaxed)) {
    // Taken before looking, so a ring between the look and the wait is not lost.
    const std::uint32_t seen = wake_.snapshot();
    next = std::max<std::size_t>(next, skip_to_.load(std::memory_order_relaxed));
    if (next < frames.size() && (have_buffer || free_.try_pop(buffer))) {
      have_buffer = true;
      Image& image = images_[buffer];
      const PixelFormat want = format_;
      Status status = Status::kOk;
      const Expected<FrameLoad> load = rec_->load_frame(camera_index_, frames[next].frame, image);
      if (!load.ok() || image.format() != want) {
        status = Status::kError;  // malformed or of another format: delivered as missing
      } else if (*load == FrameLoad::kMissing) {
        status = Status::kMissing;
      }
      if (image.format() != want)  // a file of another format was read: back to the pool's
        image.allocate(width_, height_, want,
                       static_cast<std::uint16_t>(want == PixelFormat::kMono8 ? 255 : 65535));
      loaded_.try_push(Loaded{buffer, static_cast<std::uint32_t>(next), status});  // has room
      have_buffer = false;
      ++next;
      continue;
    }
    wake_.wait(seen, kLoaderWaitNs);
  }
}

}  // namespace mocap::hal
