// Design: a bounded single-producer/single-consumer queue of (possibly large) trivially
// copyable items whose policy, when full, is to DROP THE OLDEST item so that the
// producer never waits and never fails (the role of iceoryx's spsc_sofi, "safely
// overflowing FIFO"). Made for a real-time thread handing frame results to a slow,
// non-real-time encoder thread: the newest data always gets in, stale data goes.
//
// Layout: `depth + 2` item buffers allocated once at construction, and the queue itself
// holds buffer INDICES, so that a large item is never copied while the other side may
// be touching it (no torn items, no data race under TSan):
//   - the producer owns one "staging" buffer; push() copies the item into it, then
//     commits its index at the tail of the index ring;
//   - the consumer owns at most one buffer at a time (front() .. release()) and hands it
//     back through a free ring (rt::SpscRing, consumer -> producer);
//   - up to `depth` committed indices wait in the index ring.
// Drop-oldest: when the ring already holds `depth` indices, the producer takes the
// oldest itself by a compare-and-swap on the read index (the consumer pops with the same
// CAS, so exactly one side wins each index), and reuses that buffer as its next staging
// buffer. Otherwise its next staging buffer comes from the free ring, which then always
// has one (counting: depth + 2 buffers = <= depth queued + <= 1 consumer's + the ones
// freed; see push()). Indices are free-running 64-bit counters (no ABA). Ring slots are
// std::atomic<uint32_t> so the consumer's speculative read of a slot the producer may be
// rewriting is not a data race; the CAS then rejects a stale read.
//
// Ownership: exactly one producer thread (push, dropped) and one consumer thread
// (front, release); size_approx/dropped from anywhere. push/front/release never block,
// never allocate and are noexcept.
#pragma once

#include <atomic>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <type_traits>

#include "core/expected.h"
#include "rt/counter.h"
#include "rt/spsc_ring.h"

namespace mocap::rt {

template <class T>
class DropOldestQueue {
  static_assert(std::is_trivially_copyable_v<T>,
                "DropOldestQueue items must be trivially copyable");

 public:
  static constexpr int kMaxDepth = 1 << 16;

  // Setup: depth in [1, kMaxDepth].
  static Expected<std::unique_ptr<DropOldestQueue>> create(int depth) {
    if (depth < 1 || depth > kMaxDepth) {
      return make_error(
          "DropOldestQueue", "depth",
          "must be in [1, " + std::to_string(kMaxDepth) + "], got " + std::to_string(depth));
    }
    return std::unique_ptr<DropOldestQueue>(new DropOldestQueue(depth));
  }
  DropOldestQueue(const DropOldestQueue&) = delete;
  DropOldestQueue& operator=(const DropOldestQueue&) = delete;

  // Producer only. Copies `item` in; when `depth` items were already waiting, the oldest
  // is dropped (counted) and false is returned. The item is always queued.
  bool push(const T& item) noexcept {
    buffers_[staging_] = item;
    // relaxed: write_idx_ is written only by this thread.
    const std::uint64_t w = write_idx_.load(std::memory_order_relaxed);
    // acquire: pairs with the consumer's release CAS in front(), so that the buffers it
    // pushed to the free ring before that pop are visible to the free-ring pop below.
    std::uint64_t r = read_idx_.load(std::memory_order_acquire);
    bool dropped = false;
    std::uint32_t next = 0;
    while (w - r >= depth_) {  // full: take the oldest ourselves
      // relaxed: the producer wrote that slot itself (before its release of write_idx_).
      const std::uint32_t oldest = ring_[r & mask_].load(std::memory_order_relaxed);
      // acq_rel on success: our claim is ordered with the consumer's pops (release
      // sequence on read_idx_); acquire on failure: r is reloaded and the consumer's
      // free-ring pushes before its pop become visible.
      if (read_idx_.compare_exchange_weak(r, r + 1, std::memory_order_acq_rel,
                                          std::memory_order_acquire)) {
        next = oldest;
        dropped = true;
        break;
      }
    }
    // relaxed: the slot is published by the release store of write_idx_ below.
    ring_[w & mask_].store(staging_, std::memory_order_relaxed);
    // release: the item's bytes in buffers_[staging_] and the slot happen-before a
    // consumer that acquires write_idx_ >= w + 1.
    write_idx_.store(w + 1, std::memory_order_release);
    if (!dropped) {
      // Not full: <= depth indices are queued now (ours included), the consumer holds
      // <= 1 buffer, so at least one of the depth + 2 buffers is in the free ring, and it
      // is visible (acquire above). The loop is a guard, never expected to repeat.
      while (!free_->try_pop(next)) {
        r = read_idx_.load(std::memory_order_acquire);  // acquire: as above
        if (write_idx_.load(std::memory_order_relaxed) - r > 1) {
          const std::uint32_t oldest = ring_[r & mask_].load(std::memory_order_relaxed);
          if (read_idx_.compare_exchange_strong(r, r + 1, std::memory_order_acq_rel,
                                                std::memory_order_acquire)) {
            next = oldest;
            dropped = true;
            break;
          }
        }
      }
    }
    staging_ = next;
    if (dropped) dropped_.add();
    return !dropped;
  }

  // Consumer only. The oldest waiting item, or nullptr when empty. The item stays valid
  // and unchanged until release() or the next front(); front() releases the previous one.
  const T* front() noexcept {
    release();
    // acquire: pairs with the producer's CAS (release part) when it dropped the oldest.
    std::uint64_t r = read_idx_.load(std::memory_order_acquire);
    for (;;) {
      // acquire: pairs with the producer's release store in push(): the slot and the
      // item bytes of every index < w are visible.
      const std::uint64_t w = write_idx_.load(std::memory_order_acquire);
      if (r == w) return nullptr;
      // relaxed: speculative; if the producer has since dropped index r and rewritten the
      // slot, read_idx_ != r and the CAS below fails.
      const std::uint32_t b = ring_[r & mask_].load(std::memory_order_relaxed);
      // acq_rel: release publishes our earlier free-ring pushes to a producer that
      // acquires read_idx_; acquire orders us after a producer's drop CAS.
      if (read_idx_.compare_exchange_weak(r, r + 1, std::memory_order_acq_rel,
                                          std::memory_order_acquire)) {
        held_ = static_cast<std::int64_t>(b);
        return &buffers_[b];
      }
    }
  }

  // Consumer only: hands the item of the last front() back (no-op if none is held).
  void release() noexcept {
    if (held_ < 0) return;
    // The free ring has room for every buffer, so this cannot fail.
    (void)free_->try_push(static_cast<std::uint32_t>(held_));
    held_ = -1;
  }

  // Any thread (hints / statistics).
  std::size_t size_approx() const noexcept {
    // relaxed: a hint, no data is read based on it.
    const std::uint64_t w = write_idx_.load(std::memory_order_relaxed);
    const std::uint64_t r = read_idx_.load(std::memory_order_relaxed);
    return w > r ? static_cast<std::size_t>(w - r) : 0;
  }
  std::uint64_t dropped() const noexcept { return dropped_.get(); }
  int depth() const noexcept { return static_cast<int>(depth_); }

 private:
  explicit DropOldestQueue(int depth)
      : depth_(static_cast<std::uint64_t>(depth)),
        mask_(next_power_of_two_at_least(static_cast<std::size_t>(depth)) - 1),
        buffers_(std::make_unique<T[]>(static_cast<std::size_t>(depth) + 2)),
        ring_(std::make_unique<std::atomic<std::uint32_t>[]>(mask_ + 1)),
        free_(std::make_unique<SpscRing<std::uint32_t>>(
            next_power_of_two_at_least(static_cast<std::size_t>(depth) + 2))) {
    for (std::size_t i = 0; i <= mask_; ++i) ring_[i].store(0, std::memory_order_relaxed);
    staging_ = 0;
    for (std::uint32_t b = 1; b < static_cast<std::uint32_t>(depth) + 2; ++b) {
      (void)free_->try_push(b);  // setup: the free ring starts with every other buffer
    }
  }

  const std::uint64_t depth_;
  const std::size_t mask_;
  std::unique_ptr<T[]> buffers_;
  std::unique_ptr<std::atomic<std::uint32_t>[]> ring_;
  std::unique_ptr<SpscRing<std::uint32_t>> free_;

  // Producer's line.
  alignas(kCacheLineBytes) std::atomic<std::uint64_t> write_idx_{0};
  std::uint32_t staging_ = 0;
  Counter dropped_;
  // Shared line: both sides CAS it.
  alignas(kCacheLineBytes) std::atomic<std::uint64_t> read_idx_{0};
  // Consumer's line.
  alignas(kCacheLineBytes) std::int64_t held_ = -1;
};

}  // namespace mocap::rt
