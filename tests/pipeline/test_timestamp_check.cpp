// TimestampCheck (pipeline/timestamp_check.h), the capture stage's clock-step test, on
// hand-made frame sequences (pure logic, no threads): honest gaps (dropped frames, a
// queued backlog, a late trigger, a slow lockstep consumer) are never steps; a clock
// that steps back or ahead by more than the margin always is, also on its way back;
// extreme timestamps from a faulty camera stay defined (UBSan).
#include <gtest/gtest.h>

#include <cstdint>
#include <limits>

#include "pipeline/timestamp_check.h"

namespace mocap::pipeline {
namespace {

constexpr std::int64_t kPeriod = 10'000'000;  // 100 Hz
constexpr std::int64_t kMs = 1'000'000;

using V = TimestampVerdict;

TEST(TimestampCheck, HonestGapsAreNotSteps) {
  TimestampCheck check(kPeriod);
  EXPECT_EQ(check.margin_ns(), 10u * kPeriod);
  std::int64_t t = 1'000 * kMs;
  // Triggered frames, dequeued 1 ms after their trigger.
  EXPECT_EQ(check.check(0, t, t + kMs, t), V::kOk);
  EXPECT_EQ(check.check(1, t + kPeriod, t + kPeriod + kMs, t + kPeriod), V::kOk);
  t += kPeriod;
  // 50 frames lost by the camera: the sequence gap explains the 500 ms.
  EXPECT_EQ(check.check(51, t + 50 * kPeriod, t + 50 * kPeriod + kMs, t + 50 * kPeriod), V::kOk);
  t += 50 * kPeriod;
  // The capture thread was descheduled 400 ms between a trigger and its dequeue: the
  // next trigger (and frame) comes 400 ms later with sequence + 1.
  EXPECT_EQ(check.check(52, t + kPeriod, t + 400 * kMs, t + kPeriod), V::kOk);
  EXPECT_EQ(check.check(53, t + 400 * kMs, t + 401 * kMs, t + 400 * kMs), V::kOk);
  t += 400 * kMs;
  // A free-running camera (no trigger) that delivered nothing for 300 ms: the host time
  // between the dequeues explains it.
  TimestampCheck free_run(kPeriod);
  EXPECT_EQ(free_run.check(7, t, t + kMs, 0), V::kOk);
  EXPECT_EQ(free_run.check(8, t + 300 * kMs, t + 301 * kMs, 0), V::kOk);
  // Exactly the margin ahead of every bound: not yet a jump.
  EXPECT_EQ(free_run.check(9, t + 300 * kMs + kPeriod + 10 * kPeriod, t + 302 * kMs, 0), V::kOk);
}

TEST(TimestampCheck, StepsBackAndAheadAreCounted) {
  TimestampCheck check(kPeriod);
  std::int64_t t = 1'000 * kMs;
  std::uint64_t s = 0;
  auto next = [&](std::int64_t offset_ns) {  // one frame per period, clock offset added
    t += kPeriod;
    ++s;
    return check.check(s, t + offset_ns, t + kMs, t);
  };
  EXPECT_EQ(next(0), V::kOk);
  EXPECT_EQ(next(0), V::kOk);
  EXPECT_EQ(next(0), V::kOk);
  EXPECT_EQ(next(5'000 * kMs), V::kJump);
  EXPECT_EQ(next(5'000 * kMs), V::kOk);  // the stepped clock runs on normally
  EXPECT_EQ(next(0), V::kBackwards);     // back to the true time
  EXPECT_EQ(next(-5'000 * kMs), V::kBackwards);
  EXPECT_EQ(next(-5'000 * kMs), V::kOk);
  EXPECT_EQ(next(0), V::kJump);  // ahead again to the true time
  // A small step: 150 ms ahead (> 10 periods), 5 ms back, a repeated timestamp.
  EXPECT_EQ(next(150 * kMs), V::kJump);
  EXPECT_EQ(next(150 * kMs - 15 * kMs), V::kBackwards);
  const std::int64_t last = t + 135 * kMs;
  EXPECT_EQ(check.check(s + 1, last, t + 2 * kMs, t), V::kBackwards);
  // Just beyond the margin.
  TimestampCheck edge(kPeriod);
  EXPECT_EQ(edge.check(0, 0, kMs, 0), V::kOk);
  EXPECT_EQ(edge.check(1, 11 * kPeriod + 1, 2 * kMs, 0), V::kJump);
  // reset(): the next frame has no predecessor.
  edge.reset();
  EXPECT_EQ(edge.check(0, 0, kMs, 0), V::kOk);
}

TEST(TimestampCheck, MarginHasAFloorAndExtremeValuesStayDefined) {
  TimestampCheck fast(1'000'000);  // 1 kHz: 10 periods = 10 ms, below the 20 ms floor
  EXPECT_EQ(fast.margin_ns(), TimestampCheck::kMinMarginNs);
  TimestampCheck zero(0);  // a nonsensical period is taken as 1 ns, margin the floor
  EXPECT_EQ(zero.margin_ns(), TimestampCheck::kMinMarginNs);
  constexpr std::int64_t kMin = std::numeric_limits<std::int64_t>::min();
  constexpr std::int64_t kMax = std::numeric_limits<std::int64_t>::max();
  TimestampCheck check(kMax);  // saturating margin
  EXPECT_EQ(check.check(0, kMin, kMin, kMin), V::kOk);
  EXPECT_EQ(check.check(~std::uint64_t{0}, kMax, kMax, kMax), V::kOk);  // within the margin
  TimestampCheck wild(kPeriod);
  EXPECT_EQ(wild.check(0, kMin, 0, 0), V::kOk);
  EXPECT_EQ(wild.check(1, kMax, 0, 0), V::kJump);
  EXPECT_EQ(wild.check(0, kMin, 0, 0), V::kBackwards);
}

}  // namespace
}  // namespace mocap::pipeline
