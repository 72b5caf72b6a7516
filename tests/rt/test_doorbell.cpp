// rt::Doorbell, the futex every idle thread sleeps on: a wait whose snapshot is stale
// returns at once; a wait nobody rings returns after its timeout (the safety net that
// bounds a lost wake-up); a ring wakes a sleeping waiter long before the timeout.
// (The two-thread ping-pong is in test_doorbell_stress.cpp.)
#include <gtest/gtest.h>

#include <atomic>
#include <cstdint>
#include <thread>

#include "core/clock.h"
#include "rt/doorbell.h"

namespace mocap::rt {
namespace {

TEST(Doorbell, AStaleSnapshotReturnsAtOnce) {
  Doorbell bell;
  const std::uint32_t seen = bell.snapshot();
  bell.ring();
  const std::int64_t t0 = monotonic_ns();
  bell.wait(seen, 10'000'000'000);  // 10 s: returning at all shows it did not sleep
  EXPECT_LT(monotonic_ns() - t0, 5'000'000'000);
  EXPECT_EQ(bell.snapshot(), seen + 1);
}

TEST(Doorbell, AWaitNobodyRingsEndsAtItsTimeout) {
  Doorbell bell;
  const std::int64_t t0 = monotonic_ns();
  bell.wait(bell.snapshot(), 20'000'000);
  const std::int64_t slept = monotonic_ns() - t0;
  EXPECT_GE(slept, 19'000'000);
  EXPECT_EQ(bell.snapshot(), 0u);
}

TEST(Doorbell, ARingWakesASleepingWaiter) {
  Doorbell bell;
  std::atomic<bool> asleep{false};
  std::int64_t slept = 0;
  std::thread waiter([&] {
    const std::uint32_t seen = bell.snapshot();
    asleep.store(true, std::memory_order_release);
    const std::int64_t t0 = monotonic_ns();
    bell.wait(seen, 60'000'000'000);  // a minute: only the ring ends it in time
    slept = monotonic_ns() - t0;
  });
  while (!asleep.load(std::memory_order_acquire)) std::this_thread::yield();
  std::this_thread::sleep_for(std::chrono::milliseconds(5));
  bell.ring();
  waiter.join();
  EXPECT_LT(slept, 30'000'000'000);
}

}  // namespace
}  // namespace mocap::rt
