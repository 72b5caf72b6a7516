// LatencyHistogram: bucket arithmetic (every value lands in a bucket whose bounds contain
// it, buckets at most 1/64 wide), percentiles against exact nearest-rank percentiles of
// random samples (never below, at most 1/64 above), interval snapshots, and a reader
// thread running while the writer records (TSan: no race, monotone counts); the offline
// LatencySamples' percentiles are the exact nearest-rank values up to its bound, the
// histogram's beyond it.
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

TEST(LatencySamples, PercentilesAreTheExactNearestRankValues) {
  std::mt19937_64 rng(12);
  std::lognormal_distribution<double> dist(13.0, 0.6);
  LatencySamples samples;
  EXPECT_EQ(samples.stats().count, 0u);
  std::vector<std::int64_t> v;
  for (int n : {1, 2, 3, 99, 100, 101, 150, 1000}) {
    samples = LatencySamples{};
    v.clear();
    samples.reserve(static_cast<std::size_t>(n));
    for (int i = 0; i < n; ++i) {
      v.push_back(static_cast<std::int64_t>(dist(rng)));
      samples.record(v.back());
    }
    std::vector<std::int64_t> sorted = v;
    std::sort(sorted.begin(), sorted.end());
    const auto exact_us = [&](double q) {  // the smallest value with >= ceil(q n) at or below
      const auto rank = static_cast<std::size_t>(std::ceil(q * static_cast<double>(n)));
      return static_cast<double>(sorted[std::max<std::size_t>(rank, 1) - 1]) * 1e-3;
    };
    const LatencyStats s = samples.stats();
    ASSERT_EQ(s.count, static_cast<std::uint64_t>(n));
    EXPECT_DOUBLE_EQ(s.p50_us, exact_us(0.5)) << n;
    EXPECT_DOUBLE_EQ(s.p99_us, exact_us(0.99)) << n;
    EXPECT_DOUBLE_EQ(s.p999_us, exact_us(0.999)) << n;
    EXPECT_DOUBLE_EQ(s.max_us, static_cast<double>(sorted.back()) * 1e-3);
    // The histogram of the same samples: never below, at most 1/64 above.
    H h;
    for (std::int64_t x : v) h.record(x);
    EXPECT_GE(h.stats().p99_us, s.p99_us - 1e-9);
    EXPECT_LE(h.stats().p99_us, s.p99_us * (1.0 + 1.0 / 64.0) + 1e-3);
  }
  // 150 frames of 1..150 us in any order: the p99 is the second-largest (rank 149), the
  // p50 rank 75, and a negative time counts as 0.
  LatencySamples frames;
  std::vector<int> us(150);
  for (int i = 0; i < 150; ++i) us[static_cast<std::size_t>(i)] = i + 1;
  std::shuffle(us.begin(), us.end(), rng);
  for (int x : us) frames.record(std::int64_t{x} * 1000);
  EXPECT_DOUBLE_EQ(frames.stats().p99_us, 149.0);
  EXPECT_DOUBLE_EQ(frames.stats().p50_us, 75.0);
  EXPECT_DOUBLE_EQ(frames.stats().max_us, 150.0);
  LatencySamples negative;
  negative.record(-5);
  EXPECT_DOUBLE_EQ(negative.stats().max_us, 0.0);
}

TEST(LatencySamples, BeyondItsBoundTheHistogramAnswersAndTheMemoryStaysBounded) {
  std::mt19937_64 rng(29);
  std::lognormal_distribution<double> dist(13.0, 0.6);
  constexpr std::size_t kBound = 1000;
  LatencySamples samples(kBound);
  H h;
  std::vector<std::int64_t> v;
  for (std::size_t i = 0; i < 5 * kBound; ++i) {
    v.push_back(static_cast<std::int64_t>(dist(rng)));
    samples.record(v.back());
    h.record(v.back());
    // Exact up to the bound, the histogram's values past it.
    if (i + 1 == kBound) {
      EXPECT_TRUE(samples.exact());
      std::vector<std::int64_t> sorted = v;
      std::sort(sorted.begin(), sorted.end());
      EXPECT_DOUBLE_EQ(samples.stats().p99_us, static_cast<double>(sorted[989]) * 1e-3);
    }
  }
  EXPECT_FALSE(samples.exact());
  const LatencyStats s = samples.stats(), expected = h.stats();
  EXPECT_EQ(s.count, 5 * kBound);
  EXPECT_DOUBLE_EQ(s.p50_us, expected.p50_us);
  EXPECT_DOUBLE_EQ(s.p99_us, expected.p99_us);
  EXPECT_DOUBLE_EQ(s.max_us, expected.max_us);
  // ...which bound the exact values of all 5000 samples from above by at most 1/64.
  std::sort(v.begin(), v.end());
  EXPECT_GE(s.p99_us, static_cast<double>(v[4949]) * 1e-3 - 1e-9);
  EXPECT_LE(s.p99_us, static_cast<double>(v[4949]) * 1e-3 * (1.0 + 1.0 / 64.0) + 1e-3);
  // A reserve beyond the bound reserves the bound.
  LatencySamples reserved(kBound);
  reserved.reserve(1'000'000'000);
  EXPECT_EQ(reserved.count(), 0u);
  EXPECT_TRUE(reserved.exact());
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
