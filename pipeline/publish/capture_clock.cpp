// Design: see capture_clock.h (moved here from ros2/ros2_mapping.cpp, unchanged, so that
// outputs built without DDS use the same conversion).
#include "pipeline/publish/capture_clock.h"

#include <time.h>

#include <limits>

namespace mocap::publish {

std::int64_t realtime_offset_ns() noexcept {
  auto ns = [](clockid_t clock) {
    timespec ts{};
    ::clock_gettime(clock, &ts);
    return static_cast<std::int64_t>(ts.tv_sec) * 1'000'000'000 + ts.tv_nsec;
  };
  std::int64_t best_span = std::numeric_limits<std::int64_t>::max(), offset = 0;
  for (int i = 0; i < 5; ++i) {  // bracket the realtime reading by two monotonic ones
    const std::int64_t m0 = ns(CLOCK_MONOTONIC);
    const std::int64_t r = ns(CLOCK_REALTIME);
    const std::int64_t m1 = ns(CLOCK_MONOTONIC);
    if (m1 - m0 < best_span) {
      best_span = m1 - m0;
      offset = r - (m0 + (m1 - m0) / 2);
    }
  }
  return offset;
}

}  // namespace mocap::publish
