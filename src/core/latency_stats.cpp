#include "core/latency_stats.h"

#include <algorithm>
#include <cmath>
#include <ctime>

namespace mocap {

void LatencyRecorder::clear() noexcept {
  samples_ns_.clear();
  max_ns_ = 0;
  count_ = 0;
  overflow_ = 0;
  sum_ns_ = 0.0;
}

LatencySummary LatencyRecorder::summary() const {
  LatencySummary s;
  s.count = count_;
  if (count_ == 0) return s;
  std::vector<std::int64_t> sorted = samples_ns_;
  std::sort(sorted.begin(), sorted.end());
  auto rank = [&](double p) {
    if (sorted.empty()) return static_cast<double>(max_ns_);
    const auto n = static_cast<double>(sorted.size());
    auto idx = static_cast<std::size_t>(std::ceil(p * n)) ;
    idx = idx == 0 ? 0 : idx - 1;
    return static_cast<double>(sorted[std::min(idx, sorted.size() - 1)]);
  };
  s.p50_us = rank(0.50) / 1000.0;
  s.p99_us = rank(0.99) / 1000.0;
  s.max_us = static_cast<double>(max_ns_) / 1000.0;
  s.mean_us = sum_ns_ / static_cast<double>(count_) / 1000.0;
  return s;
}

std::int64_t monotonic_ns() noexcept {
  timespec ts{};
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return static_cast<std::int64_t>(ts.tv_sec) * 1000000000LL + ts.tv_nsec;
}

}  // namespace mocap
