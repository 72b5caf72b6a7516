// DropOldestQueue, single thread: FIFO order, drop-oldest when full with the count, the
// consumer's item stays intact while the producer overflows, depth validation, and no
// allocation in push/front/release.
#include <gtest/gtest.h>

#include <array>
#include <cstdint>

#include "rt/drop_oldest_queue.h"
#include "tests/support/alloc_counter.h"

namespace mocap::rt {
namespace {

struct Big {
  std::uint64_t seq = 0;
  std::array<std::uint64_t, 64> fill{};
};

Big make(std::uint64_t s) {
  Big b;
  b.seq = s;
  b.fill.fill(s * 3 + 1);
  return b;
}

TEST(DropOldestQueue, RejectsBadDepth) {
  EXPECT_FALSE(DropOldestQueue<Big>::create(0).ok());
  EXPECT_FALSE(DropOldestQueue<Big>::create(-3).ok());
  const auto e = DropOldestQueue<Big>::create(DropOldestQueue<Big>::kMaxDepth + 1);
  ASSERT_FALSE(e.ok());
  EXPECT_NE(e.error().message.find("depth"), std::string::npos);
}

TEST(DropOldestQueue, FifoWithinDepth) {
  auto q = std::move(DropOldestQueue<Big>::create(4).value());
  EXPECT_EQ(q->front(), nullptr);
  for (std::uint64_t i = 0; i < 4; ++i) EXPECT_TRUE(q->push(make(i)));
  EXPECT_EQ(q->size_approx(), 4u);
  for (std::uint64_t i = 0; i < 4; ++i) {
    const Big* b = q->front();
    ASSERT_NE(b, nullptr);
    EXPECT_EQ(b->seq, i);
    EXPECT_EQ(b->fill[63], i * 3 + 1);
  }
  EXPECT_EQ(q->front(), nullptr);
  EXPECT_EQ(q->dropped(), 0u);
}

TEST(DropOldestQueue, DropsOldestWhenFull) {
  auto q = std::move(DropOldestQueue<Big>::create(3).value());
  for (std::uint64_t i = 0; i < 10; ++i) EXPECT_EQ(q->push(make(i)), i < 3) << i;
  EXPECT_EQ(q->dropped(), 7u);
  for (std::uint64_t i = 7; i < 10; ++i) {
    const Big* b = q->front();
    ASSERT_NE(b, nullptr);
    EXPECT_EQ(b->seq, i);
  }
  EXPECT_EQ(q->front(), nullptr);
}

TEST(DropOldestQueue, HeldItemSurvivesOverflow) {
  auto q = std::move(DropOldestQueue<Big>::create(1).value());
  ASSERT_TRUE(q->push(make(1)));
  const Big* held = q->front();
  ASSERT_NE(held, nullptr);
  for (std::uint64_t i = 2; i < 50; ++i) q->push(make(i));
  EXPECT_EQ(held->seq, 1u);  // the consumer's buffer was never reused
  EXPECT_EQ(held->fill[0], 4u);
  const Big* next = q->front();
  ASSERT_NE(next, nullptr);
  EXPECT_EQ(next->seq, 49u);
  EXPECT_EQ(q->dropped(), 47u);
}

TEST(DropOldestQueue, NoAllocationAfterCreate) {
  auto q = std::move(DropOldestQueue<Big>::create(8).value());
  test::AllocationScope counter;
  for (std::uint64_t i = 0; i < 1000; ++i) {
    q->push(make(i));
    if (i % 3 == 0) (void)q->front();
    if (i % 7 == 0) q->release();
  }
  EXPECT_EQ(counter.count(), 0u);
}

}  // namespace
}  // namespace mocap::rt
