// Design: see latency_histogram.h. Report-time code: walks the 2304 buckets (or sorts the
// offline samples).
#include "core/latency_histogram.h"

#include <algorithm>
#include <cmath>

namespace mocap {
namespace {

// The rank of the q-th percentile among `total` samples (1-based): ceil(q * total), >= 1.
std::uint64_t nearest_rank(std::uint64_t total, double q) {
  const double want = std::ceil(q * static_cast<double>(total));
  return std::max<std::uint64_t>(1, static_cast<std::uint64_t>(want));
}

// Nearest rank: the smallest value with at least ceil(q * count) samples at or below it.
template <class CountAt>
std::int64_t percentile_ns(std::uint64_t total, double q, std::int64_t max_ns, CountAt count_at) {
  if (total == 0) return 0;
  const std::uint64_t rank = nearest_rank(total, q);
  std::uint64_t seen = 0;
  for (std::size_t b = 0; b < LatencyHistogram::kBuckets; ++b) {
    seen += count_at(b);
    if (seen >= rank) return std::min(LatencyHistogram::upper_bound_of(b), max_ns);
  }
  return max_ns;
}

}  // namespace

LatencySamples::LatencySamples(std::size_t max_exact)
    : max_exact_(max_exact), histogram_(std::make_unique<LatencyHistogram>()) {}
LatencySamples::~LatencySamples() = default;
LatencySamples::LatencySamples(LatencySamples&&) noexcept = default;
LatencySamples& LatencySamples::operator=(LatencySamples&&) noexcept = default;

void LatencySamples::reserve(std::size_t n) { samples_.reserve(std::min(n, max_exact_)); }

void LatencySamples::record(std::int64_t ns) {
  if (ns < 0) ns = 0;
  if (!histogram_) histogram_ = std::make_unique<LatencyHistogram>();  // moved from
  histogram_->record(ns);
  if (samples_.size() < max_exact_) samples_.push_back(ns);
}

std::uint64_t LatencySamples::count() const noexcept {
  return histogram_ ? histogram_->count() : 0;
}

LatencyStats LatencySamples::stats() const {
  if (!exact()) return histogram_->stats();
  LatencyStats s;
  s.count = samples_.size();
  if (samples_.empty()) return s;
  std::vector<std::int64_t> sorted = samples_;
  std::sort(sorted.begin(), sorted.end());
  const auto at = [&](double q) {
    const std::uint64_t rank = std::min<std::uint64_t>(nearest_rank(s.count, q), s.count);
    return static_cast<double>(sorted[static_cast<std::size_t>(rank - 1)]) * 1e-3;
  };
  s.p50_us = at(0.50);
  s.p99_us = at(0.99);
  s.p999_us = at(0.999);
  s.max_us = static_cast<double>(sorted.back()) * 1e-3;
  double sum_ns = 0.0;
  for (const std::int64_t v : sorted) sum_ns += static_cast<double>(v);
  s.mean_us = sum_ns / static_cast<double>(s.count) * 1e-3;
  return s;
}

void LatencyHistogram::reset() noexcept {
  // relaxed: no reader relies on ordering between these fields (file comment).
  for (auto& b : buckets_) b.store(0, std::memory_order_relaxed);
  count_.store(0, std::memory_order_relaxed);
  sum_ns_.store(0, std::memory_order_relaxed);
  max_ns_.store(0, std::memory_order_relaxed);
}

double LatencyHistogram::percentile_us(double q) const noexcept {
  std::uint64_t total = 0;
  // relaxed loads throughout: approximate while the writer runs (file comment). The
  // total is the sum of the buckets read here, so the rank is always reachable.
  for (const auto& b : buckets_) total += b.load(std::memory_order_relaxed);
  const std::int64_t max = std::max(max_ns(), std::int64_t{0});
  const std::int64_t ns = percentile_ns(
      total, q, max, [&](std::size_t b) { return buckets_[b].load(std::memory_order_relaxed); });
  return static_cast<double>(ns) * 1e-3;
}

LatencySnapshot LatencyHistogram::snapshot() const {
  LatencySnapshot s;
  s.buckets.resize(kBuckets);
  // relaxed: see percentile_us(); count is the sum of the copied buckets.
  for (std::size_t b = 0; b < kBuckets; ++b) {
    s.buckets[b] = buckets_[b].load(std::memory_order_relaxed);
    s.count += s.buckets[b];
  }
  s.sum_ns = sum_ns_.load(std::memory_order_relaxed);
  s.max_ns = max_ns_.load(std::memory_order_relaxed);
  return s;
}

LatencySnapshot LatencySnapshot::since(const LatencySnapshot& earlier) const {
  LatencySnapshot d;
  d.buckets.resize(buckets.size());
  std::size_t highest = 0;
  for (std::size_t b = 0; b < buckets.size(); ++b) {
    const std::uint64_t before = b < earlier.buckets.size() ? earlier.buckets[b] : 0;
    d.buckets[b] = buckets[b] >= before ? buckets[b] - before : 0;
    d.count += d.buckets[b];
    if (d.buckets[b] > 0) highest = b;
  }
  d.sum_ns = sum_ns >= earlier.sum_ns ? sum_ns - earlier.sum_ns : 0;
  d.max_ns = d.count == 0 ? 0 : std::min(LatencyHistogram::upper_bound_of(highest), max_ns);
  return d;
}

LatencyStats LatencySnapshot::stats() const {
  LatencyStats s;
  s.count = count;
  if (count == 0) return s;
  const auto at = [&](std::size_t b) { return b < buckets.size() ? buckets[b] : 0; };
  s.p50_us = static_cast<double>(percentile_ns(count, 0.50, max_ns, at)) * 1e-3;
  s.p99_us = static_cast<double>(percentile_ns(count, 0.99, max_ns, at)) * 1e-3;
  s.p999_us = static_cast<double>(percentile_ns(count, 0.999, max_ns, at)) * 1e-3;
  s.max_us = static_cast<double>(max_ns) * 1e-3;
  s.mean_us = static_cast<double>(sum_ns) / static_cast<double>(count) * 1e-3;
  return s;
}

}  // namespace mocap
