// Single-threaded behaviour of SpscRing: creation errors, empty/full, wrap-around over
// many laps, FIFO order, and no heap allocation in push/pop.
#include <gtest/gtest.h>

#include <cstdint>

#include "rt/spsc_ring.h"
#include "tests/support/alloc_counter.h"

namespace mocap::rt {
namespace {

TEST(SpscRing, CreateRejectsNonPowerOfTwo) {
  EXPECT_FALSE(SpscRing<int>::create(0).ok());
  EXPECT_FALSE(SpscRing<int>::create(1).ok());
  auto bad = SpscRing<int>::create(12);
  ASSERT_FALSE(bad.ok());
  EXPECT_NE(bad.error().message.find("power of two"), std::string::npos) << bad.error().message;
  auto good = SpscRing<int>::create(16);
  ASSERT_TRUE(good.ok());
  EXPECT_EQ(good->capacity(), 16u);
}

TEST(SpscRing, EmptyPopFailsAndLeavesOutput) {
  SpscRing<int> ring(4);
  int out = 42;
  EXPECT_FALSE(ring.try_pop(out));
  EXPECT_EQ(out, 42);
  EXPECT_FALSE(ring.can_pop());
  EXPECT_TRUE(ring.empty_approx());
}

TEST(SpscRing, FullAtCapacityUsesEverySlot) {
  SpscRing<int> ring(8);
  for (int i = 0; i < 8; ++i) EXPECT_TRUE(ring.try_push(i)) << i;
  EXPECT_FALSE(ring.try_push(99));
  EXPECT_EQ(ring.size_approx(), 8u);
  int out = -1;
  ASSERT_TRUE(ring.try_pop(out));
  EXPECT_EQ(out, 0);
  EXPECT_TRUE(ring.try_push(8));  // one slot freed -> one push succeeds
  EXPECT_FALSE(ring.try_push(100));
  for (int expect = 1; expect <= 8; ++expect) {
    ASSERT_TRUE(ring.try_pop(out));
    EXPECT_EQ(out, expect);
  }
  EXPECT_FALSE(ring.try_pop(out));
}

TEST(SpscRing, WrapsAroundManyLapsInOrder) {
  SpscRing<std::uint64_t> ring(4);
  std::uint64_t next_push = 0, next_pop = 0;
  // Uneven batches so that the indices cross the wrap point at every offset.
  for (int round = 0; round < 1000; ++round) {
    const int pushes = 1 + round % 4;
    for (int i = 0; i < pushes; ++i) {
      if (ring.try_push(next_push)) ++next_push;
    }
    const int pops = 1 + (round * 7) % 4;
    for (int i = 0; i < pops; ++i) {
      std::uint64_t v = 0;
      if (!ring.try_pop(v)) break;
      ASSERT_EQ(v, next_pop);
      ++next_pop;
    }
    ASSERT_LE(next_push - next_pop, 4u);
  }
  EXPECT_GT(next_pop, 1000u);
}

struct Descriptor {
  std::uint32_t slot;
  std::uint64_t sequence;
  std::int64_t timestamp_ns;
};

TEST(SpscRing, CarriesTrivialStructsAndMoves) {
  SpscRing<Descriptor> ring(2);
  ASSERT_TRUE(ring.try_push({3, 7, -5}));
  SpscRing<Descriptor> moved(std::move(ring));
  Descriptor d{};
  ASSERT_TRUE(moved.try_pop(d));
  EXPECT_EQ(d.slot, 3u);
  EXPECT_EQ(d.sequence, 7u);
  EXPECT_EQ(d.timestamp_ns, -5);
}

TEST(SpscRing, PushPopAllocateNothing) {
  SpscRing<Descriptor> ring(64);
  test::AllocationScope scope;
  Descriptor d{};
  for (std::uint64_t i = 0; i < 10000; ++i) {
    ASSERT_TRUE(ring.try_push({static_cast<std::uint32_t>(i % 64), i, 0}));
    if (i % 3 == 0) {
      ASSERT_TRUE(ring.try_push({0, i, 1}));
    }
    ASSERT_TRUE(ring.try_pop(d));
    if (i % 3 == 0) {
      ASSERT_TRUE(ring.try_pop(d));
    }
  }
  EXPECT_EQ(scope.count(), 0u);
}

TEST(SpscRing, IndicesLiveOnSeparateCacheLines) {
  // The layout is part of the design (no false sharing between the two sides).
  EXPECT_GE(sizeof(SpscRing<int>), 4 * kCacheLineBytes);
  EXPECT_EQ(alignof(SpscRing<int>), kCacheLineBytes);
}

}  // namespace
}  // namespace mocap::rt
