// Design: the one clock of the project: CLOCK_MONOTONIC in nanoseconds, the clock of
// the cameras' trigger timestamps, the live output and every latency measurement.
// noexcept; monotonic_ns() is a vDSO read (no syscall).
#pragma once

#include <cstdint>

namespace mocap {

std::int64_t monotonic_ns() noexcept;
// Sleeps until an absolute CLOCK_MONOTONIC deadline (no drift over long runs; resumes
// after signals).
void sleep_until_ns(std::int64_t deadline_ns) noexcept;

}  // namespace mocap
