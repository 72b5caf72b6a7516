// Two threads hand a token back and forth thousands of times through two rt::Doorbells
// and never sleep into a timeout, so no ring between a snapshot and its wait is lost.
// A wait may also return early with nothing new (a ring's futex wake-up delayed past the
// wait it was meant for wakes the next one): that is no lost ring, so a timeout is a wait
// that lasted its whole timeout. Run under TSan by the concurrency job.
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <cstdint>
#include <thread>

#include "rt/doorbell.h"

namespace mocap::rt {
namespace {

#if defined(__SANITIZE_THREAD__) || defined(__SANITIZE_ADDRESS__)
constexpr int kRounds = 5'000;
#else
constexpr int kRounds = 50'000;
#endif
constexpr std::int64_t kTimeoutNs = 2'000'000'000;

TEST(DoorbellStress, APingPongNeverLosesARing) {
  // Each side waits for the other's token on its own bell with a 2 s timeout; a wait
  // that lasts the whole timeout could only come from a lost ring (the other side rings
  // right after it passes the token).
  Doorbell to_a, to_b;
  std::atomic<int> token{0};  // even: a's turn; odd: b's turn
  std::atomic<int> timeouts{0};
  const auto side = [&](int parity, Doorbell& mine, Doorbell& other) {
    for (int r = 0; r < kRounds; ++r) {
      for (;;) {
        const std::uint32_t seen = mine.snapshot();
        // acquire: pairs with the other side's release store of its turn.
        if (token.load(std::memory_order_acquire) % 2 == parity) break;
        const auto t0 = std::chrono::steady_clock::now();
        mine.wait(seen, kTimeoutNs);
        if (std::chrono::steady_clock::now() - t0 >= std::chrono::nanoseconds(kTimeoutNs))
          timeouts.fetch_add(1, std::memory_order_relaxed);
      }
      // release: the turn is handed over with everything before it.
      token.fetch_add(1, std::memory_order_release);
      other.ring();
    }
  };
  std::thread b([&] { side(1, to_b, to_a); });
  side(0, to_a, to_b);
  b.join();
  EXPECT_EQ(token.load(), 2 * kRounds);
  EXPECT_EQ(timeouts.load(), 0);
}

}  // namespace
}  // namespace mocap::rt
