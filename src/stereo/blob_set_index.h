// Design: the N-view merge's duplicate lookup: "the first earlier hypothesis with exactly
// this blob set" in O(1) instead of a comparison with every earlier hypothesis. An open
// addressing hash table (linear probing, power-of-two size >= 2 x capacity, so at most half
// full) of hypothesis indices; the keys stay in the caller's array (keys[value]) and are
// compared in full, so a hash collision never merges two sets. Entries carry the frame's
// generation stamp: clear() is O(1) (a full reset only when the 32-bit stamp wraps), and
// a frame probes only a table part sized for its own count.
// Capacity is fixed at create(); find_or_insert() on a full table inserts nothing and
// returns kFull (the caller counts it and falls back to the linear comparison).
#pragma once

#include <algorithm>
#include <bit>
#include <cstdint>
#include <cstring>
#include <vector>

#include "core/camera_set.h"
#include "core/expected.h"

namespace mocap {

class BlobSetIndex {
 public:
  static constexpr int kFull = -2;

  static Expected<BlobSetIndex> create(int capacity) {
    if (capacity < 1) return Error{"blob set index: capacity must be positive"};
    std::size_t size = 16;
    while (size < 2 * static_cast<std::size_t>(capacity)) size *= 2;
    BlobSetIndex index;
    index.capacity_ = capacity;
    index.limit_ = capacity;
    index.mask_ = size - 1;
    index.slots_.assign(size, Slot{});
    return index;
  }

  // Starts a frame of at most `expected` entries (more are refused: kFull): forgets
  // every entry, and probes only the first power of two >= 2 x expected slots, so a
  // small frame stays in a small part of the table (cache).
  void clear(int expected) noexcept {
    count_ = 0;
    limit_ = std::clamp(expected, 0, capacity_);
    std::size_t size = 16;
    while (size < 2 * static_cast<std::size_t>(limit_)) size *= 2;
    mask_ = size - 1;
    if (++generation_ == 0) {
      for (Slot& s : slots_) s.stamp = 0;
      generation_ = 1;
    }
  }

  // keys[value] is the set. Returns the value stored for an equal set (the first one
  // inserted this frame), or inserts `value` and returns -1; kFull when full.
  int find_or_insert(const BlobRefs* keys, int value) noexcept {
    const BlobRefs& key = keys[value];
    for (std::size_t s = hash(key) & mask_;; s = (s + 1) & mask_) {
      Slot& slot = slots_[s];
      if (slot.stamp != generation_) {
        if (count_ >= limit_) return kFull;
        slot.stamp = generation_;
        slot.value = value;
        ++count_;
        return -1;
      }
      if (keys[slot.value] == key) return slot.value;
    }
  }

 private:
  struct Slot {
    std::uint32_t stamp = 0;
    int value = -1;
  };

  BlobSetIndex() = default;

  // Cameras 0..7 as two words (an 8-camera rig hashes what it always did); a camera
  // above 7 folds its entry in (bits of the mask above 7).
  static std::size_t hash(const BlobRefs& key) noexcept {
    static_assert(sizeof(BlobRefs::Array) >= 16, "BlobRefs: at least 8 x int16");
    std::uint64_t w[2];
    std::memcpy(w, key.indices().data(), sizeof(w));
    std::uint64_t h = w[0] * 0x9E3779B97F4A7C15ull ^ (w[1] + 0x632BE59BD9B4E019ull);
    for (CameraMask m = key.mask() >> 8; m != 0; m &= m - 1) {
      const int c = 8 + std::countr_zero(m);
      h = (h ^ static_cast<std::uint64_t>(static_cast<std::uint16_t>(key[c])) << (c % 48)) *
          0x9E3779B97F4A7C15ull;
    }
    h ^= h >> 31;
    h *= 0xD6E8FEB86659FD93ull;
    h ^= h >> 32;
    return static_cast<std::size_t>(h);
  }

  int capacity_ = 0;
  int limit_ = 0;  // entries allowed this frame
  int count_ = 0;
  std::size_t mask_ = 0;
  std::uint32_t generation_ = 0;
  std::vector<Slot> slots_;
};

}  // namespace mocap
