// Two threads on one DropOldestQueue: the producer never waits; the consumer sees an
// in-order subsequence of intact items (every word of an item checked, so a torn or
// reused buffer shows), and received + dropped == sent once drained. With a slow
// consumer drops must occur; with a consumer that keeps up on a deep queue, the
// invariants still hold. Run under TSan by the concurrency job.
#include <gtest/gtest.h>

#include <array>
#include <atomic>
#include <cstdint>
#include <thread>

#include "rt/drop_oldest_queue.h"

namespace mocap::rt {
namespace {

#if defined(__SANITIZE_THREAD__) || defined(__SANITIZE_ADDRESS__)
constexpr std::uint64_t kDropOldestItems = 100'000;
#else
constexpr std::uint64_t kDropOldestItems = 1'000'000;
#endif

struct StressItem {
  std::uint64_t seq = 0;
  std::array<std::uint64_t, 15> words{};
};

struct Result {
  std::uint64_t received = 0, bad = 0, out_of_order = 0;
};

Result run(int depth, int consumer_spin) {
  auto q = std::move(DropOldestQueue<StressItem>::create(depth).value());
  std::atomic<bool> done{false};
  std::thread producer([&] {
    StressItem it;
    for (std::uint64_t i = 1; i <= kDropOldestItems; ++i) {
      it.seq = i;
      it.words.fill(i * 0x9E3779B97F4A7C15ull);
      q->push(it);
    }
    done.store(true, std::memory_order_release);
  });
  Result r;
  std::uint64_t last = 0;
  volatile std::uint64_t sink = 0;
  for (;;) {
    const bool finished = done.load(std::memory_order_acquire);
    const StressItem* it = q->front();
    if (it == nullptr) {
      if (finished) break;
      continue;
    }
    for (std::uint64_t w : it->words) {
      if (w != it->seq * 0x9E3779B97F4A7C15ull) ++r.bad;
    }
    if (it->seq <= last) ++r.out_of_order;
    last = it->seq;
    ++r.received;
    for (int k = 0; k < consumer_spin; ++k) sink = sink + 1;  // a slow encoder
  }
  producer.join();
  EXPECT_EQ(r.received + q->dropped(), kDropOldestItems);
  EXPECT_EQ(last, kDropOldestItems);  // the newest item always gets through
  return r;
}

TEST(DropOldestQueueStress, SlowConsumerDropsOldestIntact) {
  const Result r = run(4, 2000);
  EXPECT_EQ(r.bad, 0u);
  EXPECT_EQ(r.out_of_order, 0u);
  EXPECT_LT(r.received, kDropOldestItems);  // the consumer is far slower: drops happened
}

TEST(DropOldestQueueStress, DepthOneAndDeepQueue) {
  for (int depth : {1, 2, 256}) {
    const Result r = run(depth, 0);
    EXPECT_EQ(r.bad, 0u) << depth;
    EXPECT_EQ(r.out_of_order, 0u) << depth;
  }
}

}  // namespace
}  // namespace mocap::rt
