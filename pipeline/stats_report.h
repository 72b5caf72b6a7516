// Design: the end-of-run report of `mocap run`: a human table (p50/p99/max per stage and
// end to end, fps, every drop counter) and the JSON file of --stats, in the layout of
// `mocap track --stats` ({"frames", "stages": {name: {p50_us, p99_us, max_us, mean_us}},
// "counters": {...}}) plus "duration_s", "fps", "triggered" and "published". Report
// time only (allocates).
#pragma once

#include <string>

#include "core/expected.h"
#include "pipeline/pipeline.h"

namespace mocap::pipeline {

std::string format_pipeline_stats(const PipelineStats& stats);
std::string pipeline_stats_json(const PipelineStats& stats);
Expected<void> write_pipeline_stats_json(const std::string& path, const PipelineStats& stats);

}  // namespace mocap::pipeline
