// Design: a bounded, wait-free single-producer/single-consumer ring of trivially
// copyable items (slot handles, small frame descriptors), in the style of
// rigtorp/SPSCQueue. Capacity is a power of two fixed at construction (the only
// allocation); indices are free-running 64-bit counters (slot = index & mask), so
// "full" is write - read == capacity and no slot is wasted. The producer's index and
// the consumer's index live on separate cache lines, and each side keeps a private
// cached copy of the other side's index: the shared index is only re-read when the
// cached value says "full" (producer) or "empty" (consumer), which removes most
// cache-line transfers. try_push/try_pop never block and never allocate.
//
// Ownership: exactly one thread calls try_push (the producer) and exactly one thread
// calls try_pop/peek-style functions (the consumer). size_approx() may be called from
// anywhere (it is a hint).
#pragma once

#include <atomic>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <new>
#include <type_traits>

#include "core/expected.h"

namespace mocap::rt {

// x86-64 and most ARM64 cores: 64-byte lines. (std::hardware_destructive_interference_size
// is not used: GCC warns that its value may differ between translation units.)
inline constexpr std::size_t kCacheLineBytes = 64;

inline constexpr bool is_power_of_two(std::size_t n) noexcept {
  return n != 0 && (n & (n - 1)) == 0;
}
// The smallest power of two >= max(n, 2): a ring capacity that holds n items.
inline constexpr std::size_t next_power_of_two_at_least(std::size_t n) noexcept {
  std::size_t p = 2;
  while (p < n) p <<= 1;
  return p;
}

template <class T>
class SpscRing {
  static_assert(std::is_trivially_copyable_v<T>, "SpscRing items must be trivially copyable");
  static_assert(std::is_default_constructible_v<T>, "SpscRing items must be default constructible");

 public:
  // Setup: capacity must be a power of two >= 2.
  static Expected<SpscRing> create(std::size_t capacity) {
    if (capacity < 2 || !is_power_of_two(capacity) || capacity > (std::size_t{1} << 30)) {
      return make_error("SpscRing", "capacity",
                        "must be a power of two in [2, 2^30], got " + std::to_string(capacity));
    }
    return SpscRing(capacity);
  }

  explicit SpscRing(std::size_t capacity)
      : capacity_(capacity), mask_(capacity - 1), slots_(std::make_unique<T[]>(capacity)) {}

  SpscRing(SpscRing&& other) noexcept
      : capacity_(other.capacity_), mask_(other.mask_), slots_(std::move(other.slots_)) {
    // Moving is setup-time only (no thread may be using either ring).
    write_idx_.store(other.write_idx_.load(std::memory_order_relaxed), std::memory_order_relaxed);
    read_idx_.store(other.read_idx_.load(std::memory_order_relaxed), std::memory_order_relaxed);
    read_idx_cache_ = other.read_idx_cache_;
    write_idx_cache_ = other.write_idx_cache_;
  }
  SpscRing(const SpscRing&) = delete;
  SpscRing& operator=(const SpscRing&) = delete;
  SpscRing& operator=(SpscRing&&) = delete;

  // Producer only. False when the ring is full (the item is not stored).
  bool try_push(const T& item) noexcept {
    // relaxed: write_idx_ is only ever written by this (the producer) thread, so
    // reading our own last store needs no synchronisation.
    const std::uint64_t w = write_idx_.load(std::memory_order_relaxed);
    if (w - read_idx_cache_ == capacity_) {
      // acquire: pairs with the consumer's release store of read_idx_ in try_pop, so
      // the consumer's read of the slot we are about to overwrite happens-before our
      // write (no write-after-read race on the slot).
      read_idx_cache_ = read_idx_.load(std::memory_order_acquire);
      if (w - read_idx_cache_ == capacity_) return false;
    }
    slots_[static_cast<std::size_t>(w) & mask_] = item;
    // release: publishes the slot's contents; pairs with the consumer's acquire load of
    // write_idx_, so a consumer that sees w + 1 also sees the item.
    write_idx_.store(w + 1, std::memory_order_release);
    return true;
  }

  // Consumer only. False when the ring is empty (`out` is untouched).
  bool try_pop(T& out) noexcept {
    // relaxed: read_idx_ is only ever written by this (the consumer) thread.
    const std::uint64_t r = read_idx_.load(std::memory_order_relaxed);
    if (r == write_idx_cache_) {
      // acquire: pairs with the producer's release store of write_idx_ in try_push, so
      // the slot's contents written before that store are visible to us.
      write_idx_cache_ = write_idx_.load(std::memory_order_acquire);
      if (r == write_idx_cache_) return false;
    }
    out = slots_[static_cast<std::size_t>(r) & mask_];
    // release: our read of the slot happens-before the producer (acquire above in
    // try_push) reuses it.
    read_idx_.store(r + 1, std::memory_order_release);
    return true;
  }

  // Consumer only: whether an item is available (refreshes the cached write index).
  bool can_pop() noexcept {
    const std::uint64_t r = read_idx_.load(std::memory_order_relaxed);  // own index
    if (r != write_idx_cache_) return true;
    // acquire: same pairing as in try_pop (a following try_pop reads the slot).
    write_idx_cache_ = write_idx_.load(std::memory_order_acquire);
    return r != write_idx_cache_;
  }

  // Any thread: a hint only (the two loads are not a consistent snapshot).
  std::size_t size_approx() const noexcept {
    // relaxed: no data is accessed based on this value.
    const std::uint64_t w = write_idx_.load(std::memory_order_relaxed);
    const std::uint64_t r = read_idx_.load(std::memory_order_relaxed);
    return w > r ? static_cast<std::size_t>(w - r) : 0;
  }
  bool empty_approx() const noexcept { return size_approx() == 0; }
  std::size_t capacity() const noexcept { return capacity_; }

 private:
  // Read-only after construction: shared freely by both sides.
  std::size_t capacity_;
  std::size_t mask_;
  std::unique_ptr<T[]> slots_;

  // Producer's line: its index (read by the consumer when its cache says "empty").
  alignas(kCacheLineBytes) std::atomic<std::uint64_t> write_idx_{0};
  // Producer-private cached copy of read_idx_.
  alignas(kCacheLineBytes) std::uint64_t read_idx_cache_ = 0;
  // Consumer's line: its index (read by the producer when its cache says "full").
  alignas(kCacheLineBytes) std::atomic<std::uint64_t> read_idx_{0};
  // Consumer-private cached copy of write_idx_.
  alignas(kCacheLineBytes) std::uint64_t write_idx_cache_ = 0;
  // Keeps the next object off the consumer's cache line.
  char pad_[kCacheLineBytes - sizeof(std::uint64_t)] = {};
};

}  // namespace mocap::rt
