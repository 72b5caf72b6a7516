// Tests of the fixed-capacity list: capacity from setup, refused pushes counted (and
// reset by clear), span and range access over the filled part only, an int-indexed
// list, and no allocation once the capacity is set.
#include <gtest/gtest.h>

#include <numeric>

#include "core/bounded_list.h"
#include "tests/support/alloc_counter.h"

namespace mocap {
namespace {

TEST(BoundedList, PushUntilFullThenCountsTheOverflow) {
  BoundedList<int> list(3);
  EXPECT_EQ(list.capacity(), 3u);
  EXPECT_TRUE(list.empty());
  for (int v : {10, 20, 30}) EXPECT_TRUE(list.push_back(v));
  EXPECT_TRUE(list.full());
  EXPECT_FALSE(list.push_back(40));
  EXPECT_FALSE(list.push_back(50));
  EXPECT_EQ(list.size(), 3u);
  EXPECT_EQ(list.overflow(), 2u);
  EXPECT_EQ(list[2], 30);  // the refused values wrote nothing
  list.clear();
  EXPECT_TRUE(list.empty());
  EXPECT_EQ(list.overflow(), 0u);
  EXPECT_EQ(list.capacity(), 3u);
}

TEST(BoundedList, SpanAndRangeCoverTheFilledPartOnly) {
  BoundedList<int> list(8);
  for (int v = 1; v <= 4; ++v) list.push_back(v);
  const BoundedList<int>& view = list;
  EXPECT_EQ(view.span().size(), 4u);
  EXPECT_EQ(std::accumulate(view.begin(), view.end(), 0), 10);
  for (int& v : list.span()) v *= 2;
  int sum = 0;
  for (int v : list) sum += v;
  EXPECT_EQ(sum, 20);
}

TEST(BoundedList, IntIndexAndNegativeCapacity) {
  BoundedList<double, int> list(-5);
  EXPECT_EQ(list.capacity(), 0);
  EXPECT_FALSE(list.push_back(1.0));
  EXPECT_EQ(list.overflow(), 1u);
  list.set_capacity(2);  // setup again: cleared, overflow forgotten
  EXPECT_EQ(list.overflow(), 0u);
  EXPECT_TRUE(list.push_back(1.5));
  EXPECT_EQ(list.size(), 1);
  EXPECT_DOUBLE_EQ(list[0], 1.5);
}

TEST(BoundedList, HotPathDoesNotAllocate) {
  BoundedList<std::uint64_t> list(64);
  test::AllocationScope scope;
  for (int frame = 0; frame < 10; ++frame) {
    list.clear();
    for (std::uint64_t v = 0; v < 100; ++v) list.push_back(v);
  }
  EXPECT_EQ(scope.count(), 0u);
  EXPECT_EQ(list.size(), 64u);
  EXPECT_EQ(list.overflow(), 36u);
}

}  // namespace
}  // namespace mocap
