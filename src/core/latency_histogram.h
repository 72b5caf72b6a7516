// Design: the pipeline's latency statistics, readable WHILE the pipeline runs. A
// log-linear histogram (HdrHistogram-style): values in ns, 64 linear sub-buckets per
// power of two, so a bucket is at most 1/64 (1.6 %) of its value wide; 2304 buckets
// cover 0 ns .. 2^41 ns (~37 min; larger values land in the last bucket, max stays
// exact). Fixed memory (18 KiB), nothing to size from the run length.
// One writer thread per histogram (its stage) and any number of readers (the main
// thread's periodic report, the health view, stats()). Every field is an atomic with a
// single writer, so record() is a relaxed load + relaxed store per field (no RMW bus
// lock), noexcept and allocation-free. Readers use relaxed loads: a reader may see a
// sample's bucket before its sum/max (or vice versa); statistics computed while running
// are therefore approximate by at most the samples in flight, and exact after the
// writer thread was joined (join synchronises).
// Percentiles are nearest-rank on the bucket counts and reported as the bucket's upper
// bound clipped to the exact maximum: never below the true value, at most 1.6 % above.
// Offline statistics, where every sample can be kept, use LatencySamples (exact).
#pragma once

#include <array>
#include <atomic>
#include <cstdint>
#include <memory>
#include <vector>

namespace mocap {

// A summary in microseconds (p999_us is the 99.9th percentile).
struct LatencyStats {
  std::uint64_t count = 0;
  double p50_us = 0.0;
  double p99_us = 0.0;
  double p999_us = 0.0;
  double max_us = 0.0;
  double mean_us = 0.0;
};

// A copy of a histogram's counts (report time: allocates).
struct LatencySnapshot {
  std::vector<std::uint64_t> buckets;
  std::uint64_t count = 0;
  std::uint64_t sum_ns = 0;
  std::int64_t max_ns = 0;

  // Samples recorded between `earlier` and this snapshot of the same histogram; the max
  // of the interval is the upper bound of its highest non-empty bucket (clipped to max).
  LatencySnapshot since(const LatencySnapshot& earlier) const;
  LatencyStats stats() const;
};

class LatencyHistogram;

// The offline form (`mocap track --stats`): the samples are kept, so the percentiles are
// the exact nearest-rank values (the histogram's may be up to 1/64 above), up to
// max_exact samples (8 bytes each; by default 2^20, 8 MiB: 2.9 hours at 100 fps). Every
// sample also goes into a histogram, whose percentiles stats() reports once a run has
// more (exact() false): the memory stays bounded however long the run. Offline code:
// record() allocates as the samples grow (reserve() ahead), stats() sorts a copy.
class LatencySamples {
 public:
  static constexpr std::size_t kDefaultMaxExact = std::size_t{1} << 20;
  explicit LatencySamples(std::size_t max_exact = kDefaultMaxExact);
  ~LatencySamples();
  LatencySamples(LatencySamples&&) noexcept;
  LatencySamples& operator=(LatencySamples&&) noexcept;

  void reserve(std::size_t n);
  void record(std::int64_t ns);
  std::uint64_t count() const noexcept;
  // Whether stats() are the exact values (count() <= max_exact).
  bool exact() const noexcept { return count() <= max_exact_; }
  LatencyStats stats() const;

 private:
  std::size_t max_exact_;
  std::vector<std::int64_t> samples_;            // the first max_exact_
  std::unique_ptr<LatencyHistogram> histogram_;  // every sample
};

class LatencyHistogram {
 public:
  static constexpr int kSubBits = 6;
  static constexpr std::int64_t kSub = std::int64_t{1} << kSubBits;  // 64
  static constexpr int kMaxShift = 34;
  static constexpr std::size_t kBuckets = static_cast<std::size_t>(kSub * (kMaxShift + 2));
  static constexpr std::int64_t kMaxTrackable = (std::int64_t{2} * kSub << kMaxShift) - 1;

  static std::size_t bucket_of(std::int64_t ns) noexcept {
    if (ns < 2 * kSub) return static_cast<std::size_t>(ns < 0 ? 0 : ns);
    if (ns > kMaxTrackable) ns = kMaxTrackable;
    const int msb = 63 - __builtin_clzll(static_cast<unsigned long long>(ns));
    const int shift = msb - kSubBits;
    return static_cast<std::size_t>(kSub * shift + (ns >> shift));
  }
  // The largest value that falls into bucket b.
  static std::int64_t upper_bound_of(std::size_t b) noexcept {
    const auto i = static_cast<std::int64_t>(b);
    if (i < 2 * kSub) return i;
    const std::int64_t shift = i / kSub - 1;
    const std::int64_t mantissa = i % kSub + kSub;
    return ((mantissa + 1) << shift) - 1;
  }

  // Writer thread only.
  void record(std::int64_t ns) noexcept {
    if (ns < 0) ns = 0;
    bump(buckets_[bucket_of(ns)], 1);
    bump(count_, 1);
    bump(sum_ns_, static_cast<std::uint64_t>(ns));
    // relaxed: single writer (see the file comment).
    if (ns > max_ns_.load(std::memory_order_relaxed)) max_ns_.store(ns, std::memory_order_relaxed);
  }
  // Writer thread only, or while no writer runs (start()).
  void reset() noexcept;

  // Any thread. count() and percentile_us() read atomics only (no allocation).
  std::uint64_t count() const noexcept { return count_.load(std::memory_order_relaxed); }
  std::int64_t max_ns() const noexcept { return max_ns_.load(std::memory_order_relaxed); }
  double percentile_us(double q) const noexcept;
  LatencySnapshot snapshot() const;
  LatencyStats stats() const { return snapshot().stats(); }

 private:
  static void bump(std::atomic<std::uint64_t>& a, std::uint64_t n) noexcept {
    // relaxed: single writer, so load + store loses nothing; readers want only an
    // untorn value (see the file comment).
    a.store(a.load(std::memory_order_relaxed) + n, std::memory_order_relaxed);
  }

  std::array<std::atomic<std::uint64_t>, kBuckets> buckets_{};
  std::atomic<std::uint64_t> count_{0};
  std::atomic<std::uint64_t> sum_ns_{0};
  std::atomic<std::int64_t> max_ns_{0};
};

}  // namespace mocap
