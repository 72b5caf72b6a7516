// Two threads hand a token back and forth thousands of times through two rt::Doorbells
// and never sleep into a timeout, so no ring between a snapshot and its wait is lost.
// Run under TSan by the concurrency job.
#include <gtest/gtest.h>

#include <atomic>
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

TEST(DoorbellStress, APingPongNeverLosesARing) {
  // Each side waits for the other's token on its own bell with a 2 s timeout; a wait
  // that ends with the bell's count unchanged is a timeout, which only a lost ring could
  // cause (the other side rings right after it passes the token).
  Doorbell to_a, to_b;
  std::atomic<int> token{0};  // even: a's turn; odd: b's turn
  std::atomic<int> timeouts{0};
  const auto side = [&](int parity, Doorbell& mine, Doorbell& other) {
    for (int r = 0; r < kRounds; ++r) {
      for (;;) {
        const std::uint32_t seen = mine.snapshot();
        // acquire: pairs with the other side's release store of its turn.
        if (token.load(std::memory_order_acquire) % 2 == parity) break;
        mine.wait(seen, 2'000'000'000);
        if (mine.snapshot() == seen && token.load(std::memory_order_acquire) % 2 != parity)
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
