// Design: how an idle stage waits for input without spinning and without locks: a
// 32-bit event counter the producers bump (ring) and the consumer sleeps on with a
// futex (wait), with a timeout as a safety net (a stage also re-checks its stop flag
// at least every timeout). The consumer takes a snapshot BEFORE checking its rings and
// waits only if the counter still equals the snapshot, so a ring between the check and
// the wait is never lost. ring() makes the futex syscall only when a waiter is
// registered (seq_cst on both sides: either the ringer sees the waiter, or the waiter
// sees the new count). noexcept and allocation-free.
#pragma once

#include <linux/futex.h>
#include <sys/syscall.h>
#include <unistd.h>

#include <atomic>
#include <cstdint>
#include <ctime>

namespace mocap::rt {

class Doorbell {
 public:
  // Consumer: the current count, to pass to wait() after finding nothing to do.
  std::uint32_t snapshot() const noexcept {
    // acquire: data pushed before a ring() we observe here is visible to us (the rings
    // themselves also synchronise; this keeps the pattern self-contained).
    return count_.load(std::memory_order_acquire);
  }

  // Any producer. Wakes up to `wake` waiters (several consumers sharing the bell: a pool
  // of workers).
  void ring(int wake = 1) noexcept {
    // seq_cst (with the seq_cst waiter registration): Dekker-style, see the comment above.
    count_.fetch_add(1, std::memory_order_seq_cst);
    if (waiters_.load(std::memory_order_seq_cst) > 0) {
      syscall(SYS_futex, raw(), FUTEX_WAKE_PRIVATE, wake, nullptr, nullptr, 0);
    }
  }

  // Consumer: sleeps until ring() after `seen` was taken, or timeout_ns passed. It may
  // also return early with the count unchanged (the futex wake-up of a ring that found
  // this consumer awake, delayed until it waited again): callers re-check their input.
  void wait(std::uint32_t seen, std::int64_t timeout_ns) noexcept {
    waiters_.fetch_add(1, std::memory_order_seq_cst);
    if (count_.load(std::memory_order_seq_cst) == seen) {
      timespec ts{};
      ts.tv_sec = timeout_ns / 1'000'000'000;
      ts.tv_nsec = timeout_ns % 1'000'000'000;
      // The kernel re-checks *raw() == seen atomically with going to sleep.
      syscall(SYS_futex, raw(), FUTEX_WAIT_PRIVATE, seen, &ts, nullptr, 0);
    }
    waiters_.fetch_sub(1, std::memory_order_seq_cst);
  }

 private:
  std::uint32_t* raw() noexcept { return reinterpret_cast<std::uint32_t*>(&count_); }
  static_assert(sizeof(std::atomic<std::uint32_t>) == sizeof(std::uint32_t));
  static_assert(std::atomic<std::uint32_t>::is_always_lock_free);

  std::atomic<std::uint32_t> count_{0};
  std::atomic<std::uint32_t> waiters_{0};
};

}  // namespace mocap::rt
