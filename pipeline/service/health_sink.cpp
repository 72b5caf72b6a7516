// Design: see health_sink.h.
#include "pipeline/service/health_sink.h"

#include <bit>
#include <cmath>

#include "core/latency_stats.h"

namespace mocap::service {

int latency_bucket(std::uint64_t latency_us) noexcept {
  if (latency_us < kSubBuckets) return static_cast<int>(latency_us);    // octaves 0..2: exact
  const int octave = static_cast<int>(std::bit_width(latency_us)) - 1;  // >= 3
  if (octave >= kOctaves) return kLatencyBuckets - 1;
  const auto sub = static_cast<int>((latency_us >> (octave - 3)) & (kSubBuckets - 1));
  return (octave - 2) * kSubBuckets + sub;
}

double bucket_upper_us(int bucket) noexcept {
  if (bucket < kSubBuckets) return static_cast<double>(bucket + 1);
  if (bucket >= kLatencyBuckets - 1) return std::ldexp(1.0, kOctaves);
  const int octave = bucket / kSubBuckets + 2;
  const int sub = bucket % kSubBuckets;
  return std::ldexp(static_cast<double>(kSubBuckets + sub + 1), octave - 3);
}

double window_quantile_us(const HealthSnapshot& now, const HealthSnapshot& before,
                          double p) noexcept {
  std::uint64_t total = 0;
  for (int b = 0; b < kLatencyBuckets; ++b) {
    const auto i = static_cast<std::size_t>(b);
    total += now.latency[i] - before.latency[i];
  }
  if (total == 0) return 0.0;
  // Nearest rank: the smallest bucket holding at least ceil(p * total) samples.
  auto rank = static_cast<std::uint64_t>(std::ceil(p * static_cast<double>(total)));
  if (rank < 1) rank = 1;
  std::uint64_t seen = 0;
  for (int b = 0; b < kLatencyBuckets; ++b) {
    const auto i = static_cast<std::size_t>(b);
    seen += now.latency[i] - before.latency[i];
    if (seen >= rank) return bucket_upper_us(b);
  }
  return bucket_upper_us(kLatencyBuckets - 1);
}

bool HealthSink::publish(const client::JointsMessage& message) noexcept {
  const std::int64_t now_ns = monotonic_ns();  // CLOCK_MONOTONIC, as capture_ns
  if (message.sequence >= next_sequence_) {
    add(dropped_, message.sequence - next_sequence_);
    next_sequence_ = message.sequence + 1;
  }
  const std::int64_t latency_ns = now_ns - message.capture_ns;
  const std::uint64_t latency_us =
      latency_ns > 0 ? static_cast<std::uint64_t>(latency_ns) / 1000 : 0;
  add(latency_[static_cast<std::size_t>(latency_bucket(latency_us))], 1);
  // relaxed: a timestamp for the status line; `frames_` below is the progress signal.
  last_ns_.store(now_ns, std::memory_order_relaxed);
  // release: a reader that sees this count (acquire) also sees this message's tallies.
  frames_.store(frames_.load(std::memory_order_relaxed) + 1, std::memory_order_release);
  return true;
}

void HealthSink::snapshot(HealthSnapshot& out) const noexcept {
  // acquire: pairs with publish()'s release, so the tallies below are at least as new.
  out.frames = frames_.load(std::memory_order_acquire);
  out.dropped = dropped_.load(std::memory_order_relaxed);  // relaxed: a tally
  out.last_ns = last_ns_.load(std::memory_order_relaxed);  // relaxed: a timestamp
  for (std::size_t i = 0; i < latency_.size(); ++i)
    out.latency[i] = latency_[i].load(std::memory_order_relaxed);  // relaxed: tallies
}

}  // namespace mocap::service
