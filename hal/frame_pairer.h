// Design: matches the frames of the rig's cameras (2..kMaxCameras) into frame sets,
// whatever backend produced them. A frame is offered as (key, handle): the key is the
// trigger sequence number (triggered cameras: exact match, tolerance 0) or the sensor
// timestamp in ns (free-running or libcamera cameras: match within tolerance of the
// frame that completes the set; the tolerance must be below half the frame period).
// Each camera's frames are assumed to arrive in increasing key order (true for every
// backend); the cameras may run ahead of each other.
//   - A frame whose partners are pending in EVERY other camera completes a set at once
//     (per camera, the closest key wins).
//   - Otherwise it waits in its camera's pending queue (fixed capacity).
//   - A pending frame is dead when some other camera has already delivered a key at or
//     beyond it + tolerance and has no pending partner for it (keys increase strictly
//     per camera, so that camera can never complete its set): it is dropped
//     (unmatched[camera]).
//   - A frame that arrives already dead (another camera is past it) is dropped too.
//   - When a camera stalls, the other cameras' queues fill; their oldest pending frame
//     is then dropped (overflow[camera]).
//   - Silent cameras (issue 29, hardware-triggered camera nodes): a camera with a
//     silent_after_ns bound that the other cameras' frames have waited for that long
//     (since the first frame that found no partner of it, whatever was dropped since)
//     is silent: the pending frames complete their sets without it (its entry then has
//     handle kAbsentHandle; counted in absent[camera] and partial), and so do the next
//     ones at once. It is used again from its first frame with a key above its last one
//     (keys that start over, a restarted camera's sequence numbers, keep it silent:
//     unmatched). Without a bound a camera is always waited for. The caller passes the
//     time (push's now_ns, expire()); the pairer reads no clock.
// Every dropped frame is handed to the caller's on_drop(camera, entry) so that its
// buffer goes back to its camera. The class keeps its two-camera name (a set of two is
// a pair). Pure logic: no clock, no I/O; noexcept and allocation-free after create().
// Cost per push: O(cameras x pending^2) comparisons, pending <= max_pending (small).
#pragma once

#include <algorithm>
#include <array>
#include <cstdint>
#include <cstdlib>
#include <limits>
#include <string>
#include <vector>

#include "core/camera_set.h"
#include "core/expected.h"
#include "rt/counter.h"

namespace mocap::hal {

// The handle of a silent camera's entry in a set completed without it.
inline constexpr std::uint32_t kAbsentHandle = 0xffffffffu;

struct PairEntry {
  std::int64_t key = 0;      // sequence number or timestamp_ns
  std::uint32_t handle = 0;  // the caller's buffer/slot handle
};

// One frame per camera; entries past the pairer's camera count are unused.
struct FramePair {
  PairEntry cam[kMaxCameras];
};

struct PairerConfig {
  std::int64_t tolerance = 0;     // 0 for sequence numbers; e.g. 1'000'000 ns for timestamps
  std::uint32_t max_pending = 8;  // per camera
  int cameras = 2;                // kMinCameras..kMaxCameras
  // Per camera: how long (ns) the others' frames wait for it before it is silent; 0:
  // always waited for.
  std::array<std::int64_t, kMaxCameras> silent_after_ns{};
};

struct PairerCounters {
  rt::Counter pairs;
  rt::Counter unmatched[kMaxCameras];  // dropped: another camera never delivered a partner
  rt::Counter overflow[kMaxCameras];   // dropped: pending queue full (another camera stalled)
  rt::Counter silent[kMaxCameras];     // times the camera was declared silent
  rt::Counter absent[kMaxCameras];     // sets completed without it (silent)
  rt::Counter partial;                 // sets completed without one or more silent cameras
};

class FramePairer {
 public:
  static Expected<FramePairer> create(const PairerConfig& config) {
    if (config.tolerance < 0) return make_error("FramePairer", "tolerance", "must be >= 0");
    if (config.max_pending < 1 || config.max_pending > 1024) {
      return make_error("FramePairer", "max_pending",
                        "must be in 1..1024, got " + std::to_string(config.max_pending));
    }
    if (config.cameras < kMinCameras || config.cameras > kMaxCameras) {
      return make_error("FramePairer", "cameras",
                        std::to_string(config.cameras) + " cameras, expected " +
                            std::to_string(kMinCameras) + ".." + std::to_string(kMaxCameras));
    }
    for (const std::int64_t b : config.silent_after_ns) {
      if (b < 0) return make_error("FramePairer", "silent_after_ns", "must be >= 0");
    }
    return FramePairer(config);
  }

  // Offers camera `camera`'s (0..cameras-1) frame. True when it completed `pair`
  // (cam[c] is camera c's frame, or kAbsentHandle for a silent camera). Frames that can
  // no longer be matched go to on_drop(camera, entry). now_ns: the caller's clock (only
  // used with silent_after_ns bounds).
  template <class OnDrop>
  bool push(int camera, const PairEntry& e, FramePair& pair, OnDrop&& on_drop,
            std::int64_t now_ns = 0) noexcept {
    const int n = config_.cameras;
    if (silent_[camera]) {
      if (has_latest_[camera] && e.key <= latest_[camera]) {  // started over: stays silent
        counters_.unmatched[camera].add();
        on_drop(camera, e);
        return false;
      }
      silent_[camera] = false;  // back
    }
    waiting_since_[camera] = 0;
    if (!has_latest_[camera] || e.key > latest_[camera]) latest_[camera] = e.key;
    has_latest_[camera] = true;
    // The closest pending partner within tolerance in every other camera.
    std::uint32_t best[kMaxCameras] = {};
    bool complete = true;
    bool dead = false;
    for (int o = 0; o < n; ++o) {
      if (o == camera) continue;
      best[o] = closest(o, e.key);
      if (best[o] == pending_[o].count && !silent_[o]) {
        complete = false;
        // Camera o's later keys are all > latest_[o] >= key + tolerance.
        if (has_latest_[o] && e.key + config_.tolerance <= latest_[o]) dead = true;
      }
    }
    bool paired = false;
    if (complete) {
      pair.cam[camera] = e;
      take_partners(camera, e.key, best, pair);
      paired = true;
    } else if (dead) {
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
      for (int o = 0; o < n; ++o) {  // the cameras it waits for
        if (o != camera && !silent_[o] && best[o] == pending_[o].count && waiting_since_[o] == 0)
          waiting_since_[o] = now_ns;
      }
    }
    // The other cameras' pending frames that camera `camera` has passed without a
    // pending partner are dead: its next keys are all > latest_[camera] >= key + tolerance.
    for (int o = 0; o < n; ++o) {
      if (o == camera) continue;
      Queue& oq = pending_[o];
      for (std::uint32_t i = 0; i < oq.count;) {
        const PairEntry p = oq.at(i);
        if (p.key + config_.tolerance <= latest_[camera] &&
            closest(camera, p.key) == pending_[camera].count) {
          counters_.unmatched[o].add();
          on_drop(o, p);
          oq.erase(i);
        } else {
          ++i;
        }
      }
    }
    return paired;
  }

  // Hands every pending frame to on_drop: at stop, uncounted; at the input's end
  // (unmatched = true), counted as unmatched (no partner will ever come).
  template <class OnDrop>
  void flush(OnDrop&& on_drop, bool unmatched = false) noexcept {
    for (int c = 0; c < config_.cameras; ++c) {
      while (pending_[c].count > 0) {
        if (unmatched) counters_.unmatched[c].add();
        on_drop(c, pending_[c].at(0));
        pending_[c].erase(0);
      }
      has_latest_[c] = false;
      silent_[c] = false;
      waiting_since_[c] = 0;
    }
  }

  // Declares silent the cameras waited for past their bound at now_ns, then completes
  // the pending set of the lowest key that no longer waits for anyone (silent cameras:
  // their pending partner, else kAbsentHandle). True when it completed `pair`; call
  // until false.
  bool expire(std::int64_t now_ns, FramePair& pair) noexcept {
    const int n = config_.cameras;
    bool any_silent = false;
    for (int c = 0; c < n; ++c) {
      const std::int64_t bound = config_.silent_after_ns[c];
      if (!silent_[c] && bound > 0 && waiting_since_[c] != 0 &&
          now_ns - waiting_since_[c] >= bound) {
        silent_[c] = true;
        waiting_since_[c] = 0;
        counters_.silent[c].add();
      }
      any_silent = any_silent || silent_[c];
    }
    if (!any_silent) return false;
    int found = -1;
    std::uint32_t found_i = 0;
    for (int c = 0; c < n; ++c) {
      if (silent_[c]) continue;
      for (std::uint32_t i = 0; i < pending_[c].count; ++i) {
        const std::int64_t key = pending_[c].at(i).key;
        if (found >= 0 && key >= pending_[found].at(found_i).key) continue;
        bool complete = true;
        for (int o = 0; o < n && complete; ++o)
          complete = o == c || silent_[o] || closest(o, key) != pending_[o].count;
        if (complete) {
          found = c;
          found_i = i;
        }
      }
    }
    if (found < 0) return false;
    const PairEntry e = pending_[found].at(found_i);
    pending_[found].erase(found_i);
    std::uint32_t best[kMaxCameras] = {};
    for (int o = 0; o < n; ++o) best[o] = o == found ? 0 : closest(o, e.key);
    pair.cam[found] = e;
    take_partners(found, e.key, best, pair);
    return true;
  }

  // The earliest time a camera waited for becomes silent (max when none will).
  std::int64_t next_silence_ns() const noexcept {
    std::int64_t t = std::numeric_limits<std::int64_t>::max();
    for (int c = 0; c < config_.cameras; ++c) {
      if (!silent_[c] && config_.silent_after_ns[c] > 0 && waiting_since_[c] != 0)
        t = std::min(t, waiting_since_[c] + config_.silent_after_ns[c]);
    }
    return t;
  }
  bool silent(int camera) const noexcept { return silent_[camera]; }

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
    for (int c = 0; c < config.cameras; ++c) pending_[c].items.resize(config.max_pending);
  }

  // Fills the set of `camera`'s frame at `key` with every other camera's partner at
  // best[o] (taken from its queue), or kAbsentHandle for a silent camera without one.
  void take_partners(int camera, std::int64_t key, const std::uint32_t* best,
                     FramePair& pair) noexcept {
    bool partial = false;
    for (int o = 0; o < config_.cameras; ++o) {
      if (o == camera) continue;
      if (best[o] == pending_[o].count) {  // silent (the caller checked)
        pair.cam[o] = PairEntry{key, kAbsentHandle};
        counters_.absent[o].add();
        partial = true;
        continue;
      }
      pair.cam[o] = pending_[o].at(best[o]);
      pending_[o].erase(best[o]);
    }
    counters_.pairs.add();
    if (partial) counters_.partial.add();
  }

  // Index of camera c's pending entry closest to `key` within tolerance; count: none.
  std::uint32_t closest(int c, std::int64_t key) const noexcept {
    const Queue& q = pending_[c];
    std::uint32_t best = q.count;
    std::int64_t best_dk = 0;
    for (std::uint32_t i = 0; i < q.count; ++i) {
      const std::int64_t dk = std::llabs(q.at(i).key - key);
      if (dk <= config_.tolerance && (best == q.count || dk < best_dk)) {
        best = i;
        best_dk = dk;
      }
    }
    return best;
  }

  PairerConfig config_;
  Queue pending_[kMaxCameras];
  std::int64_t latest_[kMaxCameras] = {};
  bool has_latest_[kMaxCameras] = {};
  bool silent_[kMaxCameras] = {};
  std::int64_t waiting_since_[kMaxCameras] = {};  // 0: no frame waits for the camera
  PairerCounters counters_;
};

}  // namespace mocap::hal
