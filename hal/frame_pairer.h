// Design: pairs the frames of the two stereo cameras, whatever backend produced them.
// A frame is offered as (key, handle): the key is the trigger sequence number
// (triggered cameras: exact match, tolerance 0) or the sensor timestamp in ns
// (free-running or libcamera cameras: match within tolerance, which must be below
// half the frame period). Each camera's frames are assumed to arrive in increasing
// key order (true for every backend); the two cameras may run ahead of each other.
//   - A frame whose partner is pending forms a pair at once (the closest key wins).
//   - Otherwise it waits in its camera's pending queue (fixed capacity).
//   - A pending frame is dead when the other camera has already delivered a key at or
//     beyond it + tolerance (keys increase strictly per camera, so no later frame can
//     match it): it is dropped (unmatched[camera]).
//   - A frame that arrives already dead (the other camera is past it) is dropped too.
//   - When a camera stalls, the other camera's queue fills; the oldest pending frame is
//     then dropped (overflow[camera]).
// Every dropped frame is handed to the caller's on_drop(camera, entry) so that its
// buffer goes back to its camera. Pure logic: no clock, no I/O; noexcept and
// allocation-free after create().
#pragma once

#include <cstdint>
#include <cstdlib>
#include <string>
#include <vector>

#include "core/expected.h"
#include "hal/rt/counter.h"

namespace mocap::hal {

struct PairEntry {
  std::int64_t key = 0;      // sequence number or timestamp_ns
  std::uint32_t handle = 0;  // the caller's buffer/slot handle
};

struct FramePair {
  PairEntry cam[2];
};

struct PairerConfig {
  std::int64_t tolerance = 0;     // 0 for sequence numbers; e.g. 1'000'000 ns for timestamps
  std::uint32_t max_pending = 8;  // per camera
};

struct PairerCounters {
  rt::Counter pairs;
  rt::Counter unmatched[2];  // dropped: the other camera never delivered a partner
  rt::Counter overflow[2];   // dropped: pending queue full (the other camera stalled)
};

class FramePairer {
 public:
  static Expected<FramePairer> create(const PairerConfig& config) {
    if (config.tolerance < 0) return make_error("FramePairer", "tolerance", "must be >= 0");
    if (config.max_pending < 1 || config.max_pending > 1024) {
      return make_error("FramePairer", "max_pending",
                        "must be in 1..1024, got " + std::to_string(config.max_pending));
    }
    return FramePairer(config);
  }

  // Offers camera `camera`'s (0 or 1) frame. True when it completed `pair` (cam[0] is
  // camera 0's frame). Frames that can no longer be paired go to on_drop(camera, entry).
  template <class OnDrop>
  bool push(int camera, const PairEntry& e, FramePair& pair, OnDrop&& on_drop) noexcept {
    const int other = 1 - camera;
    if (!has_latest_[camera] || e.key > latest_[camera]) latest_[camera] = e.key;
    has_latest_[camera] = true;
    bool paired = false;
    Queue& oq = pending_[other];
    // The closest pending partner within tolerance.
    std::uint32_t best = oq.count;
    std::int64_t best_dk = 0;
    for (std::uint32_t i = 0; i < oq.count; ++i) {
      const std::int64_t dk = std::llabs(oq.at(i).key - e.key);
      if (dk <= config_.tolerance && (best == oq.count || dk < best_dk)) {
        best = i;
        best_dk = dk;
      }
    }
    if (best != oq.count) {
      pair.cam[camera] = e;
      pair.cam[other] = oq.at(best);
      oq.erase(best);
      counters_.pairs.add();
      paired = true;
    } else if (has_latest_[other] && e.key + config_.tolerance <= latest_[other]) {
      // The other camera's later keys are all > latest_[other] >= key + tolerance.
      counters_.unmatched[camera].add();
      on_drop(camera, e);
    } else {
      Queue& q = pending_[camera];
      if (q.count == q.capacity()) {
        counters_.overflow[camera].add();
        on_drop(camera, q.at(0));
        q.erase(0);
      }
      q.push_back(e);
    }
    // The other camera's pending frames that camera `camera` has reached are dead: its
    // next keys are all > latest_[camera] >= key + tolerance.
    while (oq.count > 0 && oq.at(0).key + config_.tolerance <= latest_[camera]) {
      counters_.unmatched[other].add();
      on_drop(other, oq.at(0));
      oq.erase(0);
    }
    return paired;
  }

  // Hands every pending frame to on_drop (at stop), without counting it.
  template <class OnDrop>
  void flush(OnDrop&& on_drop) noexcept {
    for (int c = 0; c < 2; ++c) {
      while (pending_[c].count > 0) {
        on_drop(c, pending_[c].at(0));
        pending_[c].erase(0);
      }
      has_latest_[c] = false;
    }
  }

  std::uint32_t pending(int camera) const noexcept { return pending_[camera].count; }
  const PairerCounters& counters() const noexcept { return counters_; }
  const PairerConfig& config() const noexcept { return config_; }

 private:
  // Arrival-ordered fixed-capacity queue (small: erase shifts).
  struct Queue {
    std::vector<PairEntry> items;
    std::uint32_t count = 0;
    std::uint32_t capacity() const noexcept { return static_cast<std::uint32_t>(items.size()); }
    const PairEntry& at(std::uint32_t i) const noexcept { return items[i]; }
    void push_back(const PairEntry& e) noexcept { items[count++] = e; }
    void erase(std::uint32_t i) noexcept {
      for (std::uint32_t j = i + 1; j < count; ++j) items[j - 1] = items[j];
      --count;
    }
  };

  explicit FramePairer(const PairerConfig& config) : config_(config) {
    for (Queue& q : pending_) q.items.resize(config.max_pending);
  }

  PairerConfig config_;
  Queue pending_[2];
  std::int64_t latest_[2] = {0, 0};
  bool has_latest_[2] = {false, false};
  PairerCounters counters_;
};

}  // namespace mocap::hal
