// Design: a preallocated pool of frame slots passed between ONE producer stage and
// ONE consumer stage by handle (a uint32 index), over two SpscRings:
//   free ring  (consumer -> producer): slots the producer may fill,
//   ready ring (producer -> consumer): filled slots, oldest first.
// Every slot is in exactly one place at any time: the free ring, the producer's hand
// (acquired, being filled), the ready ring, or the consumer's hand (popped, being
// processed). Both rings have capacity >= slot count, so pushes never fail and each
// ring keeps its SPSC roles: the producer only pops `free` and pushes `ready`, the
// consumer only pops `ready` and pushes `free`. Slot contents need no atomics: handing
// a handle through a ring (release store / acquire load) publishes the slot's data.
//
// Drop policy ("the capture never blocks"): the producer never waits.
//   - Consumer side, drop-oldest: pop_fresh(fresh) takes the oldest ready slot that
//     `fresh` accepts (e.g. "at most 25 ms old"), or else the newest, and hands every
//     older ready slot it passes over straight back to the free ring, counting each in
//     skipped(). A stage that falls behind thus catches up on the frames that still
//     matter and sheds the rest; pop() (all fresh) and pop_latest() (none) are its ends.
//   - Producer side: acquire() fails only when every slot is queued or held (the
//     consumer has not run for slot_count - 1 frames); the producer then drops the
//     incoming frame, counted in dropped(). Size the pool so this cannot happen while
//     the consumer is alive (slots >= queue depth the consumer may skip + 2).
// All hot-path calls are noexcept, lock-free and allocation-free.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "core/expected.h"
#include "rt/counter.h"
#include "rt/spsc_ring.h"

namespace mocap::rt {

using SlotHandle = std::uint32_t;
inline constexpr SlotHandle kInvalidSlot = ~SlotHandle{0};

template <class Slot>
class SlotPool {
 public:
  // Setup: builds `slot_count` slots with make_slot(index) (allocate image buffers
  // there); all slots start free.
  template <class MakeSlot>
  static Expected<SlotPool> create(std::uint32_t slot_count, MakeSlot&& make_slot) {
    if (slot_count < 2 || slot_count > (1u << 20)) {
      return make_error("SlotPool", "slot_count",
                        "must be in [2, 2^20], got " + std::to_string(slot_count));
    }
    std::vector<Slot> slots;
    slots.reserve(slot_count);
    for (std::uint32_t i = 0; i < slot_count; ++i) slots.push_back(make_slot(i));
    SlotPool pool(std::move(slots));
    for (SlotHandle h = 0; h < slot_count; ++h) pool.free_.try_push(h);  // cannot fail
    return pool;
  }

  SlotPool(SlotPool&&) noexcept = default;
  SlotPool(const SlotPool&) = delete;
  SlotPool& operator=(const SlotPool&) = delete;
  SlotPool& operator=(SlotPool&&) = delete;

  std::uint32_t slot_count() const noexcept { return static_cast<std::uint32_t>(slots_.size()); }
  // The slot of a handle the caller currently owns.
  Slot& operator[](SlotHandle h) noexcept { return slots_[h]; }
  const Slot& operator[](SlotHandle h) const noexcept { return slots_[h]; }

  // ---- producer thread ----
  // A free slot to fill. False (and one dropped frame counted) when none is free.
  bool acquire(SlotHandle& out) noexcept {
    if (free_.try_pop(out)) return true;
    dropped_.add();
    return false;
  }
  // Hands a filled slot to the consumer (never fails: the ready ring holds every slot).
  void publish(SlotHandle h) noexcept {
    ready_.try_push(h);
    published_.add();
  }
  // (An acquired slot that ends up unused stays in the producer's hand for its next
  // frame: only the consumer pushes to the free ring.)
  std::uint64_t published() const noexcept { return published_.get(); }
  std::uint64_t dropped() const noexcept { return dropped_.get(); }

  // ---- consumer thread ----
  // The oldest ready slot (FIFO); false when none.
  bool pop(SlotHandle& out) noexcept { return ready_.try_pop(out); }
  // The newest ready slot; every older ready slot is released and counted as skipped.
  bool pop_latest(SlotHandle& out) noexcept {
    return pop_fresh(out, [](const Slot&) { return false; });
  }
  // The oldest ready slot that fresh(slot) accepts, or else the newest: every older ready
  // slot it passes over is released and counted as skipped (pop(): every slot fresh;
  // pop_latest(): none). The consumer's catch-up policy, e.g. "at most N ms old".
  template <class Fresh>
  bool pop_fresh(SlotHandle& out, Fresh&& fresh) noexcept {
    SlotHandle h;
    if (!ready_.try_pop(h)) return false;
    SlotHandle next;
    while (!fresh(static_cast<const Slot&>(slots_[h])) && ready_.try_pop(next)) {
      free_.try_push(h);  // cannot fail: the free ring holds every slot
      skipped_.add();
      h = next;
    }
    out = h;
    return true;
  }
  // Returns a processed slot to the producer.
  void release(SlotHandle h) noexcept { free_.try_push(h); }
  std::uint64_t skipped() const noexcept { return skipped_.get(); }

  // Any thread (hint): slots waiting for the consumer.
  std::size_t ready_approx() const noexcept { return ready_.size_approx(); }

 private:
  explicit SlotPool(std::vector<Slot> slots)
      : slots_(std::move(slots)),
        free_(next_power_of_two_at_least(slots_.size())),
        ready_(next_power_of_two_at_least(slots_.size())) {}

  std::vector<Slot> slots_;
  SpscRing<SlotHandle> free_;   // consumer -> producer
  SpscRing<SlotHandle> ready_;  // producer -> consumer
  Counter published_;           // written by the producer
  Counter dropped_;             // written by the producer
  Counter skipped_;             // written by the consumer
};

}  // namespace mocap::rt
