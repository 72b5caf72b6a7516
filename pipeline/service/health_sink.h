// Design: the pipeline's health as the service sees it, measured where it matters: at
// the end of the pipeline. HealthSink is one more OutputSink next to the outputs;
// on the publish thread it counts every message, the frames dropped on the way (gaps
// in the sequence numbers, which count every triggered frame) and the trigger-to-sink
// latency in a fixed log-linear histogram (8 sub-buckets per power of two of
// microseconds: <= 12.5 % resolution, 1 us .. 16 s). publish() is noexcept,
// allocation-free and lock-free: single writer, relaxed atomic tallies (rt::Counter
// style). Any thread may take a snapshot(); the histogram and the counters are read one
// by one, so a snapshot taken while frames flow may be off by the frame in flight,
// which is fine for a status line and a watchdog (progress only needs `frames` to be
// monotonic). The Supervisor (supervisor.h) reads it through HealthSource so that
// another progress source (e.g. pipeline::Pipeline's own counters) can stand in.
#pragma once

#include <array>
#include <atomic>
#include <cstdint>

#include "client/joints_message.h"
#include "pipeline/publish/output_sink.h"

namespace mocap::service {

inline constexpr int kSubBuckets = 8;  // per power of two
inline constexpr int kOctaves = 24;    // 1 us .. 2^24 us (16.8 s)
// 0..7 us exactly (8 buckets), then octaves 3..23 with 8 sub-buckets each, + overflow.
inline constexpr int kLatencyBuckets = kSubBuckets * (kOctaves - 2) + 1;

// Bucket of a latency in microseconds, and the upper edge (us) of a bucket.
int latency_bucket(std::uint64_t latency_us) noexcept;
double bucket_upper_us(int bucket) noexcept;

struct HealthSnapshot {
  std::uint64_t frames = 0;   // messages that reached the end of the pipeline
  std::uint64_t dropped = 0;  // triggered frames that never did (sequence gaps)
  std::int64_t last_ns = 0;   // CLOCK_MONOTONIC of the last message (0: none yet)
  std::array<std::uint64_t, kLatencyBuckets> latency{};  // trigger-to-sink histogram
};

// p-quantile (0..1) in microseconds of the difference `now - before` of two
// histograms (upper bucket edge; 0 when the window holds no sample).
double window_quantile_us(const HealthSnapshot& now, const HealthSnapshot& before,
                          double p) noexcept;

class HealthSource {
 public:
  virtual ~HealthSource() = default;
  // Any thread.
  virtual void snapshot(HealthSnapshot& out) const noexcept = 0;
};

class HealthSink final : public publish::OutputSink, public HealthSource {
 public:
  const char* name() const noexcept override { return "health"; }
  // Publish thread only.
  bool publish(const publish::FrameResult& frame) noexcept override {
    return publish(frame.joints);
  }
  bool publish(const client::JointsMessage& message) noexcept;
  publish::OutputCounters counters() const noexcept override {
    publish::OutputCounters c;
    c.published = frames_.load(std::memory_order_relaxed);  // relaxed: a tally
    return c;
  }
  void snapshot(HealthSnapshot& out) const noexcept override;

 private:
  using Tally = std::atomic<std::uint64_t>;
  static void add(Tally& t, std::uint64_t n) noexcept {
    // relaxed: single writer (the publish thread), readers only need untorn values.
    t.store(t.load(std::memory_order_relaxed) + n, std::memory_order_relaxed);
  }
  Tally frames_{0};
  Tally dropped_{0};
  std::atomic<std::int64_t> last_ns_{0};
  std::array<Tally, kLatencyBuckets> latency_{};
  std::uint64_t next_sequence_ = 0;  // publish thread only
};

}  // namespace mocap::service
