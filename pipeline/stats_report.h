// Design: the reports of `mocap run`: a human table at the end (p50/p99/p99.9/max per
// stage and end to end, fps, every drop counter), a one-line periodic progress report
// (the last interval's trigger-to-publish percentiles and the cumulative counters), and
// the JSON file of --stats, in the layout of `mocap track --stats` ({"frames", "stages":
// {name: {count, p50_us, p99_us, p999_us, max_us, mean_us}}, "counters": {...}}) plus
// "duration_s", "fps", "triggered" and "published". Report time only (allocates).
#pragma once

#include <string>

#include "core/expected.h"
#include "core/latency_histogram.h"
#include "pipeline/pipeline.h"

namespace mocap::pipeline {

std::string format_pipeline_stats(const PipelineStats& stats);
// One line: "t=12.0s fps=100.0 e2e(last 5.0s) p50=.. p99=.. p99.9=.. max=..us
// published=.. dropped=.. cam silent=../..ms blob overflow=../.. clock steps=../..", with
// one '/'-separated value per camera of the rig.
std::string format_progress_line(double elapsed_s, double interval_s,
                                 const LatencyStats& interval_e2e, const PipelineHealth& health);
std::string pipeline_stats_json(const PipelineStats& stats);
Expected<void> write_pipeline_stats_json(const std::string& path, const PipelineStats& stats);

}  // namespace mocap::pipeline
