// Two threads on one SpscRing: millions of items arrive complete and in order when the
// consumer keeps up (the producer retries), and when the producer drops on full, what
// arrives is an in-order subsequence and received + dropped == sent. Run under TSan by
// the concurrency job (fewer items there: TSan is ~10x slower).
#include <gtest/gtest.h>

#include <atomic>
#include <cstdint>
#include <thread>

#include "rt/spsc_ring.h"

namespace mocap::rt {
namespace {

#if defined(__SANITIZE_THREAD__) || defined(__SANITIZE_ADDRESS__)
constexpr std::uint64_t kItems = 300'000;
#else
constexpr std::uint64_t kItems = 5'000'000;
#endif

TEST(SpscRingStress, NoLossNoReorderWhenProducerRetries) {
  SpscRing<std::uint64_t> ring(1024);
  std::thread producer([&] {
    for (std::uint64_t i = 0; i < kItems; ++i) {
      while (!ring.try_push(i)) std::this_thread::yield();
    }
  });
  std::uint64_t expect = 0;
  std::uint64_t mismatches = 0;
  while (expect < kItems) {
    std::uint64_t v;
    if (ring.try_pop(v)) {
      if (v != expect) ++mismatches;
      expect = v + 1;
    }
  }
  producer.join();
  EXPECT_EQ(mismatches, 0u);
  std::uint64_t extra;
  EXPECT_FALSE(ring.try_pop(extra));
}

struct Item {
  std::uint64_t seq;
  std::uint64_t check;  // a second word, to catch torn or stale slot reads
};

TEST(SpscRingStress, DropsAreCountedWhenFull) {
  SpscRing<Item> ring(8);
  std::uint64_t dropped = 0;
  std::thread producer([&] {
    for (std::uint64_t i = 0; i < kItems; ++i) {
      if (!ring.try_push({i, ~i})) ++dropped;  // the capture never blocks
    }
    while (!ring.try_push({kItems, ~kItems})) std::this_thread::yield();  // end marker
  });
  std::uint64_t received = 0, last = 0, bad = 0, out_of_order = 0;
  bool first = true;
  for (;;) {
    Item it;
    if (!ring.try_pop(it)) continue;
    if (it.check != ~it.seq) ++bad;
    if (it.seq == kItems) break;
    if (!first && it.seq <= last) ++out_of_order;
    first = false;
    last = it.seq;
    ++received;
    if (received % 64 == 0) {
      for (int spin = 0; spin < 200; ++spin) {
        std::atomic_signal_fence(std::memory_order_seq_cst);  // a slow consumer: forces drops
      }
    }
  }
  producer.join();
  EXPECT_EQ(bad, 0u);
  EXPECT_EQ(out_of_order, 0u);
  EXPECT_EQ(received + dropped, kItems);
  EXPECT_GT(received, 0u);
}

}  // namespace
}  // namespace mocap::rt
