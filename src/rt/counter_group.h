// Design: a stage's counters, each named where it is declared (PX4's perf_alloc): a
// NamedCounter or a CameraCounters registers itself in its CounterGroup when it is
// constructed, so the group can report every counter by name, in declaration order,
// without a second list that could forget one:
//
//   struct CaptureCounters {
//     rt::CounterGroup group;
//     rt::NamedCounter triggered{group, "triggered"};
//     rt::CameraCounters dequeue_timeouts{group, "dequeue_timeouts_cam#"};
//   };
//
// A '#' in a name stands for a camera index: a CameraCounters (one counter per camera,
// kMaxCameras of them) reports one entry per camera of the rig; a NamedCounter in a
// group made for one camera (CounterGroup(3)) reports that camera ("detect#_skipped" ->
// "detect3_skipped"). Counting is rt::Counter's (one writer, relaxed, noexcept);
// registration happens at construction (setup time) into a fixed array; report() is
// report-time code (allocates). Groups and their counters are neither copied nor moved
// (the group holds their addresses): allocate the owning object once.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "core/camera_set.h"
#include "rt/counter.h"

namespace mocap::rt {

using CounterReport = std::vector<std::pair<std::string, std::uint64_t>>;

// A name pattern with its '#' (if any) replaced by `camera`.
inline std::string counter_name(const char* pattern, int camera) {
  std::string out;
  for (const char* p = pattern; *p != '\0'; ++p) {
    if (*p == '#')
      out += std::to_string(camera);
    else
      out += *p;
  }
  return out;
}

class CounterGroup {
 public:
  static constexpr std::size_t kCapacity = 48;
  // camera: the camera a one-camera stage's '#' names (-1: none).
  explicit CounterGroup(int camera = -1) noexcept : camera_(camera) {}
  CounterGroup(const CounterGroup&) = delete;
  CounterGroup& operator=(const CounterGroup&) = delete;

  // Construction of a member counter only. A group is sized for its stage: overflowing
  // it is a programming error caught by the first test that reports (the name
  // "counter_group_overflow" appears).
  void add(const char* pattern, const Counter* counters, int per_camera) noexcept {
    if (size_ == kCapacity) {
      overflow_ = true;
      return;
    }
    entries_[size_++] = Entry{pattern, counters, per_camera};
  }

  // Appends (name, value) of every counter; CameraCounters for cameras 0..cameras-1.
  void report(int cameras, CounterReport& out) const {
    for (std::size_t i = 0; i < size_; ++i) {
      const Entry& e = entries_[i];
      if (e.per_camera == 0) {
        out.emplace_back(counter_name(e.pattern, camera_), e.counters[0].get());
        continue;
      }
      for (int c = 0; c < cameras && c < e.per_camera; ++c)
        out.emplace_back(counter_name(e.pattern, c), e.counters[c].get());
    }
    if (overflow_) out.emplace_back("counter_group_overflow", 1);
  }
  int camera() const noexcept { return camera_; }

 private:
  struct Entry {
    const char* pattern = "";
    const Counter* counters = nullptr;
    int per_camera = 0;  // 0: one counter; else an array of that many (one per camera)
  };
  std::array<Entry, kCapacity> entries_{};
  std::size_t size_ = 0;
  int camera_ = -1;
  bool overflow_ = false;
};

class NamedCounter : public Counter {
 public:
  NamedCounter(CounterGroup& group, const char* name) noexcept { group.add(name, this, 0); }
  NamedCounter(const NamedCounter&) = delete;
  NamedCounter& operator=(const NamedCounter&) = delete;
};

class CameraCounters {
 public:
  CameraCounters(CounterGroup& group, const char* pattern) noexcept {
    group.add(pattern, counters_.data(), kMaxCameras);
  }
  CameraCounters(const CameraCounters&) = delete;
  CameraCounters& operator=(const CameraCounters&) = delete;

  Counter& operator[](std::size_t camera) noexcept { return counters_[camera]; }
  const Counter& operator[](std::size_t camera) const noexcept { return counters_[camera]; }

 private:
  std::array<Counter, kMaxCameras> counters_{};
};

}  // namespace mocap::rt
