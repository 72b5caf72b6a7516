// Single-threaded behaviour of SlotPool: every slot is in exactly one place, FIFO and
// latest-wins consumption, drop counting, slot contents preallocated and preserved,
// and no heap allocation in the steady state.
#include <gtest/gtest.h>

#include <algorithm>
#include <set>
#include <vector>

#include "core/image.h"
#include "rt/slot_pool.h"
#include "tests/support/alloc_counter.h"

namespace mocap::rt {
namespace {

struct FrameSlot {
  Image image;
  std::uint64_t sequence = 0;
};

Expected<SlotPool<FrameSlot>> make_pool(std::uint32_t n) {
  return SlotPool<FrameSlot>::create(n, [](std::uint32_t) {
    FrameSlot s;
    s.image.allocate(64, 48, PixelFormat::kMono8, 255);
    return s;
  });
}

TEST(SlotPool, RejectsBadCounts) {
  EXPECT_FALSE(make_pool(0).ok());
  EXPECT_FALSE(make_pool(1).ok());
  EXPECT_TRUE(make_pool(3).ok());  // not a power of two is fine: rings round up
}

TEST(SlotPool, EverySlotIsOwnedOnce) {
  auto pool = make_pool(5);
  ASSERT_TRUE(pool.ok());
  std::vector<SlotHandle> held;
  SlotHandle h;
  while (pool->acquire(h)) held.push_back(h);
  EXPECT_EQ(held.size(), 5u);
  EXPECT_EQ(pool->dropped(), 1u);  // the failed acquire counts one dropped frame
  std::set<SlotHandle> unique(held.begin(), held.end());
  EXPECT_EQ(unique.size(), 5u);
  EXPECT_EQ(*unique.rbegin(), 4u);

  // Publish three, release them after consumption: they become acquirable again.
  for (int i = 0; i < 3; ++i) pool->publish(held[static_cast<std::size_t>(i)]);
  std::vector<SlotHandle> consumed;
  while (pool->pop(h)) consumed.push_back(h);
  EXPECT_EQ(consumed, std::vector<SlotHandle>(held.begin(), held.begin() + 3));  // FIFO
  for (SlotHandle c : consumed) pool->release(c);
  std::vector<SlotHandle> again;
  while (pool->acquire(h)) again.push_back(h);
  std::sort(again.begin(), again.end());
  std::vector<SlotHandle> expect(held.begin(), held.begin() + 3);
  std::sort(expect.begin(), expect.end());
  EXPECT_EQ(again, expect);
}

TEST(SlotPool, SlotContentsTravelWithTheHandle) {
  auto pool = make_pool(4);
  ASSERT_TRUE(pool.ok());
  SlotHandle h;
  ASSERT_TRUE(pool->acquire(h));
  FrameSlot& s = (*pool)[h];
  const std::uint8_t* buffer = s.image.data();
  s.sequence = 77;
  s.image.row8(10)[20] = 200;
  pool->publish(h);
  SlotHandle got;
  ASSERT_TRUE(pool->pop(got));
  EXPECT_EQ(got, h);
  EXPECT_EQ((*pool)[got].sequence, 77u);
  EXPECT_EQ((*pool)[got].image.view().row8(10)[20], 200);
  EXPECT_EQ((*pool)[got].image.data(), buffer);  // zero copy: same preallocated buffer
}

TEST(SlotPool, PopLatestSkipsAndRecyclesOlderFrames) {
  auto pool = make_pool(6);
  ASSERT_TRUE(pool.ok());
  SlotHandle h;
  std::vector<SlotHandle> order;
  for (std::uint64_t seq = 0; seq < 4; ++seq) {
    ASSERT_TRUE(pool->acquire(h));
    (*pool)[h].sequence = seq;
    pool->publish(h);
    order.push_back(h);
  }
  SlotHandle latest;
  ASSERT_TRUE(pool->pop_latest(latest));
  EXPECT_EQ((*pool)[latest].sequence, 3u);
  EXPECT_EQ(pool->skipped(), 3u);
  EXPECT_FALSE(pool->pop(h));
  // The three skipped slots plus the two never used are free again; `latest` is held.
  int free_count = 0;
  while (pool->acquire(h)) {
    EXPECT_NE(h, latest);
    ++free_count;
  }
  EXPECT_EQ(free_count, 5);
  EXPECT_FALSE(pool->pop_latest(h));  // nothing ready: no skip counted
  EXPECT_EQ(pool->skipped(), 3u);
}

TEST(SlotPool, PopFreshTakesTheOldestFreshSlotInOrderAndSkipsOnlyStaleOnes) {
  auto pool = make_pool(8);
  ASSERT_TRUE(pool.ok());
  SlotHandle h;
  for (std::uint64_t seq = 0; seq < 5; ++seq) {
    ASSERT_TRUE(pool->acquire(h));
    (*pool)[h].sequence = seq;
    pool->publish(h);
  }
  // "Fresh": sequence >= 2. 0 and 1 are stale and skipped; 2, 3, 4 come in order.
  const auto fresh = [](const FrameSlot& s) { return s.sequence >= 2; };
  for (std::uint64_t want = 2; want < 5; ++want) {
    ASSERT_TRUE(pool->pop_fresh(h, fresh));
    EXPECT_EQ((*pool)[h].sequence, want);
    pool->release(h);
  }
  EXPECT_EQ(pool->skipped(), 2u);
  EXPECT_FALSE(pool->pop_fresh(h, fresh));
  // A stale slot with nothing newer is still taken: the newest is never skipped.
  ASSERT_TRUE(pool->acquire(h));
  (*pool)[h].sequence = 0;
  pool->publish(h);
  ASSERT_TRUE(pool->pop_fresh(h, fresh));
  EXPECT_EQ((*pool)[h].sequence, 0u);
  EXPECT_EQ(pool->skipped(), 2u);
}

TEST(SlotPool, ProducerDropsWhenConsumerHoldsEverything) {
  auto pool = make_pool(2);
  ASSERT_TRUE(pool.ok());
  SlotHandle a, b, c;
  ASSERT_TRUE(pool->acquire(a));
  pool->publish(a);
  ASSERT_TRUE(pool->acquire(b));
  pool->publish(b);
  EXPECT_FALSE(pool->acquire(c));
  EXPECT_FALSE(pool->acquire(c));
  EXPECT_EQ(pool->dropped(), 2u);
  EXPECT_EQ(pool->published(), 2u);
}

TEST(SlotPool, SteadyStateAllocatesNothing) {
  auto pool = make_pool(4);
  ASSERT_TRUE(pool.ok());
  test::AllocationScope scope;
  SlotHandle h;
  for (std::uint64_t i = 0; i < 5000; ++i) {
    if (pool->acquire(h)) {
      (*pool)[h].sequence = i;
      (*pool)[h].image.row8(0)[0] = static_cast<std::uint8_t>(i);
      pool->publish(h);
    }
    if (i % 2 == 1) {
      if (pool->pop_latest(h)) pool->release(h);
    }
  }
  EXPECT_EQ(scope.count(), 0u);
}

}  // namespace
}  // namespace mocap::rt
