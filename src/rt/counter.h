// Design: failure/event counters of the hot path. Each counter has exactly one writer
// thread (the stage that owns it) and any number of readers (statistics, tests), so an
// increment is a relaxed load + relaxed store (no read-modify-write bus lock) and a
// read is a relaxed load: counters order nothing, they are only tallies.
#pragma once

#include <atomic>
#include <cstdint>

namespace mocap::rt {

class Counter {
 public:
  Counter() = default;
  // Setup-time only (moving the owning object before threads start).
  Counter(const Counter& other) noexcept : value_(other.get()) {}
  Counter& operator=(const Counter&) = delete;

  // Writer thread only.
  void add(std::uint64_t n = 1) noexcept {
    // relaxed: single writer, so load+store cannot lose an update; readers only need
    // an eventually visible, untorn value, which any atomic access provides.
    value_.store(value_.load(std::memory_order_relaxed) + n, std::memory_order_relaxed);
  }
  void reset() noexcept { value_.store(0, std::memory_order_relaxed); }  // writer only
  // Any thread.
  std::uint64_t get() const noexcept { return value_.load(std::memory_order_relaxed); }

 private:
  std::atomic<std::uint64_t> value_{0};
};

}  // namespace mocap::rt
