// Design: per-stage latency statistics of `mocap track --stats` in the spec's
// stats.json layout ({"frames": N, "stages": {"detect": {"p50_us","p99_us","max_us"},
// ...}}), plus documented extra keys: "mean_us" per stage and a "counters" object.
#pragma once

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "core/expected.h"
#include "core/latency_histogram.h"
#include "track/frame_processor.h"

namespace mocap {

// The stages' times in the one latency histogram (core/latency_histogram.h: percentiles
// at most 1/64 above the exact nearest-rank value, fixed memory whatever the length).
struct TrackStats {
  void record(const StageTimesNs& t) noexcept {
    load.record(t.load);
    detect.record(t.detect);
    triangulate.record(t.triangulate);
    identify.record(t.identify);
    angles.record(t.angles);
    frame.record(t.frame);
  }

  std::int64_t frames = 0;
  LatencyHistogram load, detect, triangulate, identify, angles, frame;
  std::vector<std::pair<std::string, std::uint64_t>> counters;  // filled at the end
};

// Counters of every stage of a processor, as (name, value) pairs.
std::vector<std::pair<std::string, std::uint64_t>> collect_counters(const FrameProcessor& p);

std::string stats_to_json(const TrackStats& stats);
Expected<void> write_stats_json(const std::string& path, const TrackStats& stats);

}  // namespace mocap
