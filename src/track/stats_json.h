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

// The stages' times (core/latency_histogram.h: LatencySamples, exact nearest-rank
// percentiles up to 2^20 frames, 48 bytes per frame; histogram percentiles beyond).
struct TrackStats {
  void reserve(std::size_t frame_count) {
    for (LatencySamples* s : {&load, &detect, &triangulate, &identify, &angles, &frame})
      s->reserve(frame_count);
  }
  void record(const StageTimesNs& t) {
    load.record(t.load);
    detect.record(t.detect);
    triangulate.record(t.triangulate);
    identify.record(t.identify);
    angles.record(t.angles);
    frame.record(t.frame);
  }

  std::int64_t frames = 0;
  LatencySamples load, detect, triangulate, identify, angles, frame;
  std::vector<std::pair<std::string, std::uint64_t>> counters;  // filled at the end
};

// Counters of every stage of a processor, as (name, value) pairs.
std::vector<std::pair<std::string, std::uint64_t>> collect_counters(const FrameProcessor& p);

std::string stats_to_json(const TrackStats& stats);
Expected<void> write_stats_json(const std::string& path, const TrackStats& stats);

}  // namespace mocap
