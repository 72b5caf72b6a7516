// Design: tells a camera clock step from an honest gap between two frames (issue 8,
// clock jumps). The capture stage runs one TimestampCheck per camera on every frame it
// dequeues and counts the verdicts (timestamp_backwards, timestamp_jumps); the frame
// itself goes on unchanged (see docs/pipeline.md, "Camera clock steps").
//   kBackwards : the timestamp is not later than the previous frame's of that camera.
//   kJump      : it advanced by more than any honest bound plus a margin. The honest
//                bounds of the step dt are: the frames missing in between (sequence gap x
//                frame period), the host time between the two dequeues (a frame may wait
//                in the camera's queue) and the host time between the software triggers
//                that preceded them (a late capture thread delays the next trigger); the
//                margin is jump_periods frame periods, at least min_margin_ns.
// So a stalled camera, a dropped frame, a late trigger or a slow lockstep consumer never
// count as a jump, while a clock that steps ahead by more than the margin always does,
// also when it steps back to the true time after a step back. Pure logic (no clock, no
// I/O): noexcept, allocation-free, one thread (the capture thread).
#pragma once

#include <algorithm>
#include <cstdint>

namespace mocap::pipeline {

enum class TimestampVerdict : std::uint8_t { kOk, kBackwards, kJump };

class TimestampCheck {
 public:
  static constexpr std::uint64_t kJumpPeriods = 10;
  static constexpr std::uint64_t kMinMarginNs = 20'000'000;    // 20 ms
  static constexpr std::uint64_t kMaxSequenceGap = 1'000'000;  // bounds the product below

  TimestampCheck() = default;
  // period_ns: the frame period (software trigger, or the free-running camera's rate);
  // values < 1 are taken as 1 ns.
  explicit TimestampCheck(std::int64_t period_ns) noexcept
      : period_ns_(static_cast<std::uint64_t>(std::max<std::int64_t>(period_ns, 1))),
        margin_ns_(std::max(saturating_mul(kJumpPeriods, period_ns_), kMinMarginNs)) {}

  // received_ns: host CLOCK_MONOTONIC when the frame was dequeued; trigger_ns: host time
  // of the last software trigger before that dequeue (0: the camera runs free).
  TimestampVerdict check(std::uint64_t sequence, std::int64_t timestamp_ns,
                         std::int64_t received_ns, std::int64_t trigger_ns) noexcept {
    const Previous prev = prev_;
    prev_ = Previous{true, sequence, timestamp_ns, received_ns, trigger_ns};
    if (!prev.valid) return TimestampVerdict::kOk;
    if (timestamp_ns <= prev.timestamp_ns) return TimestampVerdict::kBackwards;
    // Out-of-order or repeated sequence numbers (a camera fault of their own) count as 1.
    const std::uint64_t gap =
        sequence > prev.sequence ? std::min(sequence - prev.sequence, kMaxSequenceGap) : 1;
    // Unsigned, saturating: any int64 timestamps (a faulty camera's too) stay defined.
    std::uint64_t honest_ns = saturating_mul(gap, period_ns_);
    honest_ns = std::max(honest_ns, forward_ns(prev.received_ns, received_ns));
    if (trigger_ns != 0 && prev.trigger_ns != 0)
      honest_ns = std::max(honest_ns, forward_ns(prev.trigger_ns, trigger_ns));
    const std::uint64_t limit = honest_ns > kMax - margin_ns_ ? kMax : honest_ns + margin_ns_;
    return forward_ns(prev.timestamp_ns, timestamp_ns) > limit ? TimestampVerdict::kJump
                                                               : TimestampVerdict::kOk;
  }

  void reset() noexcept { prev_ = Previous{}; }
  std::uint64_t margin_ns() const noexcept { return margin_ns_; }

 private:
  static constexpr std::uint64_t kMax = ~std::uint64_t{0};
  // b - a when b > a (exact in uint64 for any int64 pair), else 0.
  static std::uint64_t forward_ns(std::int64_t a, std::int64_t b) noexcept {
    return b > a ? static_cast<std::uint64_t>(b) - static_cast<std::uint64_t>(a) : 0;
  }
  static std::uint64_t saturating_mul(std::uint64_t a, std::uint64_t b) noexcept {
    return b != 0 && a > kMax / b ? kMax : a * b;
  }

  struct Previous {
    bool valid = false;
    std::uint64_t sequence = 0;
    std::int64_t timestamp_ns = 0, received_ns = 0, trigger_ns = 0;
  };
  std::uint64_t period_ns_ = 10'000'000;
  std::uint64_t margin_ns_ = kJumpPeriods * 10'000'000;
  Previous prev_{};
};

}  // namespace mocap::pipeline
