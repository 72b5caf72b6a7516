// LatencyHistogram: bucket arithmetic (every value lands in a bucket whose bounds contain
// it, buckets at most 1/64 wide), percentiles against exact nearest-rank percentiles of
// random samples (never below, at most 1/64 above), interval snapshots, and a reader
// thread running while the writer records (TSan: no race, monotone counts).
#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <random>
#include <thread>
#include <vector>

#include "core/latency_histogram.h"

namespace mocap {
namespace {

using H = LatencyHistogram;

TEST(LatencyHistogram, BucketsContainTheirValuesAndAreNarrow) {
  std::mt19937_64 rng(7);
  std::int64_t lower_of_next = 0;
  for (std::size_t b = 0; b < H::kBuckets; ++b) {  // buckets tile [0, max] without holes
    const std::int64_t hi = H::upper_bound_of(b);
    ASSERT_GE(hi, lower_of_next) << b;
    EXPECT_EQ(H::bucket_of(lower_of_next), b);
    EXPECT_EQ(H::bucket_of(hi), b);
    EXPECT_LE(static_cast<double>(hi - lower_of_next + 1),
              std::max(1.0, static_cast<double>(lower_of_next) / 64.0))
        << b;
    lower_of_next = hi + 1;
  }
  EXPECT_EQ(lower_of_next - 1, H::kMaxTrackable);
  EXPECT_EQ(H::bucket_of(H::kMaxTrackable * 4), H::kBuckets - 1);
  EXPECT_EQ(H::bucket_of(-5), 0u);
  for (int i = 0; i < 10000; ++i) {
    const auto v = static_cast<std::int64_t>(rng() % (std::uint64_t{1} << 40));
    const std::size_t b = H::bucket_of(v);
    EXPECT_LE(v, H::upper_bound_of(b));
    EXPECT_TRUE(b == 0 || v > H::upper_bound_of(b - 1));
  }
}

TEST(LatencyHistogram, PercentilesMatchExactNearestRankWithin1Point6Percent) {
  std::mt19937_64 rng(11);
  std::lognormal_distribution<double> dist(13.0, 0.6);  // ~0.5 ms median, heavy tail
  H h;
  std::vector<std::int64_t> v;
  for (int i = 0; i < 20000; ++i) {
    v.push_back(static_cast<std::int64_t>(dist(rng)));
    h.record(v.back());
  }
  std::sort(v.begin(), v.end());
  const LatencyStats s = h.stats();
  ASSERT_EQ(s.count, v.size());
  const auto exact_us = [&](double q) {
    const auto rank = static_cast<std::size_t>(std::ceil(q * static_cast<double>(v.size())));
    return static_cast<double>(v[rank - 1]) * 1e-3;
  };
  const std::pair<double, double> checks[] = {
      {0.5, s.p50_us}, {0.99, s.p99_us}, {0.999, s.p999_us}};
  for (const auto& [q, got] : checks) {
    EXPECT_GE(got, exact_us(q) - 1e-9) << q;
    EXPECT_LE(got, exact_us(q) * (1.0 + 1.0 / 64.0) + 1e-3) << q;
  }
  EXPECT_DOUBLE_EQ(s.max_us, static_cast<double>(v.back()) * 1e-3);
  double sum = 0.0;
  for (std::int64_t x : v) sum += static_cast<double>(x);
  EXPECT_NEAR(s.mean_us, sum / static_cast<double>(v.size()) * 1e-3, 1e-6);
  EXPECT_DOUBLE_EQ(h.percentile_us(0.99), s.p99_us);
}

TEST(LatencyHistogram, IntervalSnapshotHoldsOnlyTheNewSamples) {
  H h;
  for (int i = 0; i < 1000; ++i) h.record(1'000'000);  // 1 ms
  const LatencySnapshot a = h.snapshot();
  for (int i = 0; i < 100; ++i) h.record(5'000'000);  // 5 ms
  const LatencyStats d = h.snapshot().since(a).stats();
  EXPECT_EQ(d.count, 100u);
  EXPECT_GE(d.p50_us, 5000.0);
  EXPECT_LE(d.p50_us, 5000.0 * (1 + 1.0 / 64));
  EXPECT_DOUBLE_EQ(d.mean_us, 5000.0);
  EXPECT_EQ(a.since(a).stats().count, 0u);
  h.reset();
  EXPECT_EQ(h.count(), 0u);
  EXPECT_EQ(h.stats().max_us, 0.0);
}

TEST(LatencyHistogram, ReaderWhileWriterRecords) {
  H h;
  std::atomic<bool> done{false};
  std::thread writer([&] {
    for (int i = 0; i < 200000; ++i) h.record(1000 + i % 5000);
    done.store(true, std::memory_order_release);
  });
  std::uint64_t last = 0;
  while (!done.load(std::memory_order_acquire)) {
    const LatencySnapshot s = h.snapshot();
    EXPECT_GE(s.count, last);
    last = s.count;
    EXPECT_LE(h.percentile_us(0.99), 6.0 + 1e-9);
  }
  writer.join();
  EXPECT_EQ(h.stats().count, 200000u);
  EXPECT_EQ(h.max_ns(), 5999);
}

}  // namespace
}  // namespace mocap
