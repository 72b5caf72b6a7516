// Design: how the pipeline reports the counters of the per-frame libraries. The blob
// detector, the stereo triangulator, the multi-view merger, the identifier and the chain
// solver keep their counters as plain integers that only the thread running them may
// touch. After every frame, the stage thread that owns such a library republishes them
// into a CounterMirror: one std::atomic<std::uint64_t> per reported field, stored relaxed
// by that single writer and loaded relaxed by any reader (health(), stats(), a status
// line). Each value is untorn and at most one frame old; like every other pipeline
// counter, the values are not a snapshot of one instant. Which fields are reported, and
// under which names, is the one table of track/counter_fields.h, shared with
// `mocap track --stats`. publish() is noexcept and allocation-free (a few ns per field
// and frame).
#pragma once

#include <array>
#include <atomic>
#include <cstddef>
#include <cstdint>

#include "track/counter_fields.h"

namespace mocap::pipeline {

template <class Source, std::size_t N>
class CounterMirror {
 public:
  using Fields = std::array<CounterField<Source>, N>;

  // The owning stage thread only (the one that runs the library).
  void publish(const Fields& fields, const Source& source) noexcept {
    for (std::size_t i = 0; i < N; ++i) {
      // relaxed: a single writer; readers only need an untorn, recent tally, and no other
      // memory is published through these values.
      values_[i].store(fields[i].read(source), std::memory_order_relaxed);
    }
  }
  // Any thread.
  std::uint64_t get(std::size_t i) const noexcept {
    return values_[i].load(std::memory_order_relaxed);  // relaxed: see publish()
  }
  static constexpr std::size_t size() noexcept { return N; }

 private:
  std::array<std::atomic<std::uint64_t>, N> values_{};
};

using DetectorMirror = CounterMirror<detect::DetectorCounters, kDetectorFields.size()>;
using StereoMirror = CounterMirror<StereoCounters, kStereoFields.size()>;
using MultiViewMirror = CounterMirror<MultiViewCounters, kMultiViewFields.size()>;
using IdentifyMirror = CounterMirror<IdentifyCounters, kIdentifyFields.size()>;
using ChainMirror = CounterMirror<ChainCounters, kChainFields.size()>;
using CoverageMirror = CounterMirror<ChainCounters, kCoverageFields.size()>;

}  // namespace mocap::pipeline
