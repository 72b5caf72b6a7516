// Two threads on a SlotPool, as a capture stage and a processing stage: the producer
// writes a pattern into the slot's buffer, the consumer checks it (a data race or a
// slot owned twice shows up as a torn pattern or a TSan report), skips to the latest,
// and at the end every slot is accounted for: published == consumed + skipped + left
// in the ready ring, and every handle is free exactly once.
#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <cstdint>
#include <thread>
#include <vector>

#include "rt/slot_pool.h"

namespace mocap::rt {
namespace {

#if defined(__SANITIZE_THREAD__) || defined(__SANITIZE_ADDRESS__)
constexpr std::uint64_t kFrames = 50'000;
#else
constexpr std::uint64_t kFrames = 1'000'000;
#endif

struct Slot {
  std::vector<std::uint64_t> payload;  // preallocated "image"
  std::uint64_t sequence = 0;
};

TEST(SlotPoolStress, OwnershipHoldsUnderConcurrency) {
  auto pool_or = SlotPool<Slot>::create(4, [](std::uint32_t) {
    return Slot{std::vector<std::uint64_t>(32), 0};
  });
  ASSERT_TRUE(pool_or.ok());
  SlotPool<Slot>& pool = *pool_or;
  std::atomic<bool> done{false};

  std::thread producer([&] {
    SlotHandle h = kInvalidSlot;
    for (std::uint64_t seq = 0; seq < kFrames; ++seq) {
      if (h == kInvalidSlot && !pool.acquire(h)) continue;  // frame dropped, counted
      Slot& s = pool[h];
      s.sequence = seq;
      for (std::uint64_t& w : s.payload) w = seq * 31 + 7;
      pool.publish(h);
      h = kInvalidSlot;
    }
    done.store(true, std::memory_order_release);
  });

  std::uint64_t consumed = 0, torn = 0, backwards = 0, last = 0;
  bool first = true;
  for (;;) {
    SlotHandle h;
    const bool got = (consumed % 3 == 0) ? pool.pop_latest(h) : pool.pop(h);
    if (!got) {
      if (done.load(std::memory_order_acquire) && pool.ready_approx() == 0) break;
      continue;
    }
    const Slot& s = pool[h];
    for (std::uint64_t w : s.payload) {
      if (w != s.sequence * 31 + 7) ++torn;
    }
    if (!first && s.sequence <= last) ++backwards;
    first = false;
    last = s.sequence;
    ++consumed;
    pool.release(h);
  }
  producer.join();

  EXPECT_EQ(torn, 0u);
  EXPECT_EQ(backwards, 0u);
  EXPECT_EQ(pool.published() + pool.dropped(), kFrames);
  EXPECT_EQ(consumed + pool.skipped(), pool.published());
  // All four slots are free again, each exactly once.
  std::vector<SlotHandle> free_slots;
  SlotHandle h;
  while (pool.acquire(h)) free_slots.push_back(h);
  std::sort(free_slots.begin(), free_slots.end());
  EXPECT_EQ(free_slots, (std::vector<SlotHandle>{0, 1, 2, 3}));
}

}  // namespace
}  // namespace mocap::rt
