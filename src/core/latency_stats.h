// Design: fixed-capacity latency recorder for per-stage timing statistics.
// Capacity is chosen at setup; record() is noexcept and allocation-free (samples past
// capacity are counted in `overflow` and folded into max only), so it can sit on the
// hot path. Percentiles are computed at report time (nearest-rank on a sorted copy).
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace mocap {

struct LatencySummary {
  std::uint64_t count = 0;
  double p50_us = 0.0;
  double p99_us = 0.0;
  double max_us = 0.0;
  double mean_us = 0.0;
};

class LatencyRecorder {
 public:
  explicit LatencyRecorder(std::size_t capacity = 0) { reserve(capacity); }
  void reserve(std::size_t capacity) { samples_ns_.reserve(capacity); }

  void record(std::int64_t duration_ns) noexcept {
    if (duration_ns < 0) duration_ns = 0;
    if (duration_ns > max_ns_) max_ns_ = duration_ns;
    ++count_;
    sum_ns_ += static_cast<double>(duration_ns);
    if (samples_ns_.size() < samples_ns_.capacity()) {
      samples_ns_.push_back(duration_ns);  // within reserved capacity: no allocation
    } else {
      ++overflow_;
    }
  }

  std::uint64_t count() const noexcept { return count_; }
  std::uint64_t overflow() const noexcept { return overflow_; }
  void clear() noexcept;

  // Setup/report time only: copies and sorts.
  LatencySummary summary() const;

 private:
  std::vector<std::int64_t> samples_ns_;
  std::int64_t max_ns_ = 0;
  std::uint64_t count_ = 0;
  std::uint64_t overflow_ = 0;
  double sum_ns_ = 0.0;
};

// Monotonic clock in nanoseconds (CLOCK_MONOTONIC), noexcept.
std::int64_t monotonic_ns() noexcept;

}  // namespace mocap
