// Design: see queued_sink.h.
#include "pipeline/publish/queued_sink.h"

#include <pthread.h>
#include <time.h>

#include <algorithm>
#include <exception>
#include <system_error>

namespace mocap::publish {
namespace {

constexpr std::int64_t kIdlePeriodNs = 100'000'000;    // idle() about every 100 ms
constexpr std::int64_t kActivePollNs = 1'000'000;      // poll period while frames arrive
constexpr std::int64_t kQuietAfterNs = 1'000'000'000;  // no frame for this long: quiet
constexpr std::int64_t kQuietPollNs = 20'000'000;      // poll period when quiet

std::int64_t monotonic_ns() noexcept {
  timespec ts{};
  ::clock_gettime(CLOCK_MONOTONIC, &ts);
  return static_cast<std::int64_t>(ts.tv_sec) * 1'000'000'000 + ts.tv_nsec;
}

}  // namespace

QueuedSink::QueuedSink(int depth)
    : queue_(
          std::move(rt::DropOldestQueue<FrameResult>::create(std::clamp(depth, 1, 1024)).value())) {
}

QueuedSink::~QueuedSink() { stop(); }

Expected<void> QueuedSink::start() {
  if (worker_.joinable()) return {};
  // relaxed: the thread start below synchronises with the worker.
  stop_.store(false, std::memory_order_relaxed);
  try {
    worker_ = std::thread([this] { worker_loop(); });
  } catch (const std::system_error& e) {
    return make_error("output", name(), std::string("cannot start the worker thread: ") + e.what());
  }
  char thread_name[16] = {};
  const char* n = name();
  std::size_t i = 0;
  for (; i < 8 && n[i] != '\0'; ++i) thread_name[i] = n[i];
  const char kSuffix[] = "_out";
  for (std::size_t k = 0; k < sizeof kSuffix; ++k) thread_name[i + k] = kSuffix[k];
  ::pthread_setname_np(worker_.native_handle(), thread_name);  // best effort
  return {};
}

void QueuedSink::stop() noexcept {
  if (!worker_.joinable()) return;
  // release: pairs with the worker's acquire load; the doorbell wakes it now.
  stop_.store(true, std::memory_order_release);
  bell_.ring();
  worker_.join();
}

bool QueuedSink::publish(const FrameResult& frame) noexcept {
  (void)queue_->push(frame);  // a drop of the oldest is counted by the queue; no wake-up:
  return true;                // the worker polls (see the header)
}

OutputCounters QueuedSink::counters() const noexcept {
  OutputCounters c;
  c.published = published_.get();
  c.failures = failures_.get();
  c.dropped = queue_->dropped();
  return c;
}

void QueuedSink::worker_loop() noexcept {
  std::int64_t last_idle_ns = monotonic_ns();
  std::int64_t last_frame_ns = 0;
  // acquire: pairs with stop()'s release store.
  while (!stop_.load(std::memory_order_acquire)) {
    const std::uint32_t seen = bell_.snapshot();
    if (const FrameResult* frame = queue_->front()) {
      last_frame_ns = monotonic_ns();
      try {
        encode(*frame);
        published_.add();
      } catch (...) {
        failures_.add();
      }
      continue;
    }
    queue_->release();  // hold no buffer while asleep
    const std::int64_t now = monotonic_ns();
    if (now - last_idle_ns >= kIdlePeriodNs) {
      last_idle_ns = now;
      try {
        idle();
      } catch (...) {
        failures_.add();
      }
    }
    const std::int64_t poll_ns = now - last_frame_ns < kQuietAfterNs ? kActivePollNs : kQuietPollNs;
    const std::int64_t to_idle_ns = kIdlePeriodNs - (monotonic_ns() - last_idle_ns);
    bell_.wait(seen, std::clamp<std::int64_t>(to_idle_ns, 100'000, poll_ns));  // stop() rings
  }
  queue_->release();
}

}  // namespace mocap::publish
