// Tests of the latency recorder: nearest-rank percentiles, overflow, no allocation.
#include <gtest/gtest.h>

#include "core/latency_stats.h"
#include "tests/support/alloc_counter.h"

namespace mocap {
namespace {

TEST(LatencyRecorder, NearestRankPercentiles) {
  LatencyRecorder rec(1000);
  for (int i = 1; i <= 100; ++i) rec.record(i * 1000);  // 1..100 us
  const LatencySummary s = rec.summary();
  EXPECT_EQ(s.count, 100u);
  EXPECT_DOUBLE_EQ(s.p50_us, 50.0);
  EXPECT_DOUBLE_EQ(s.p99_us, 99.0);
  EXPECT_DOUBLE_EQ(s.max_us, 100.0);
  EXPECT_DOUBLE_EQ(s.mean_us, 50.5);
}

TEST(LatencyRecorder, OverflowIsCountedAndMaxKept) {
  LatencyRecorder rec(10);
  for (int i = 0; i < 20; ++i) rec.record(1000);
  rec.record(9000000);
  EXPECT_EQ(rec.count(), 21u);
  EXPECT_EQ(rec.overflow(), 11u);
  EXPECT_DOUBLE_EQ(rec.summary().max_us, 9000.0);
}

TEST(LatencyRecorder, RecordDoesNotAllocate) {
  LatencyRecorder rec(4096);
  test::AllocationScope scope;
  for (int i = 0; i < 10000; ++i) rec.record(i);
  EXPECT_EQ(scope.count(), 0u);
}

TEST(LatencyRecorder, EmptySummaryIsZero) {
  LatencyRecorder rec(4);
  const LatencySummary s = rec.summary();
  EXPECT_EQ(s.count, 0u);
  EXPECT_EQ(s.max_us, 0.0);
}

}  // namespace
}  // namespace mocap
