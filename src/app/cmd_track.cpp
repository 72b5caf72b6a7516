// `mocap track REC --targets targets.yaml [--model model.yaml] --out DIR [--stats
// stats.json] [--truth GT_DIR]`: offline tracking of a recording through the same
// stages as the live pipeline (src/track). --truth (extension) compares the outputs
// with the simulator's ground truth and prints the accuracy. --config (extension) takes
// the detection, stereo and identification thresholds from a `mocap run` configuration
// file (its other sections are validated but not used). markers.csv is always written;
// --c3d FILE and --trc FILE (spec extension) export the labelled trajectories.
#include <cstdio>
#include <memory>
#include <string>

#include "app/command_registry.h"
#include "app/progress.h"
#include "config/run_config.h"
#include "track/offline_tracker.h"

namespace mocap::app {
namespace {

struct TrackArgs {
  std::string recording, targets, model, out, stats, truth, config, c3d, trc;
  bool quiet = false;
  int threads = 2;
};

int run_track(const TrackArgs& a) {
  OfflineTrackOptions opt;
  opt.recording_dir = a.recording;
  opt.targets_path = a.targets;
  opt.model_path = a.model;
  opt.out_dir = a.out;
  opt.stats_path = a.stats;
  opt.truth_dir = a.truth;
  opt.c3d_path = a.c3d;
  opt.trc_path = a.trc;
  opt.detect_threads = a.threads;
  if (!a.config.empty()) {
    auto cfg = config::load_run_config(a.config);
    if (!cfg) return fail(cfg.error().message);
    opt.config = cfg->tracker;
  }
  std::unique_ptr<ProgressBar> progress;
  opt.progress = [&](std::int64_t done, std::int64_t total) {
    if (!progress) progress = std::make_unique<ProgressBar>("track", total);
    progress->update(done);
  };
  int warnings = 0;
  opt.warn = [&](const std::string& m) {
    if (progress) progress->finish();
    if (++warnings <= 20) std::fprintf(stderr, "mocap: warning: %s\n", m.c_str());
    if (warnings == 21) std::fprintf(stderr, "mocap: warning: further warnings suppressed\n");
  };
  auto result = track_recording(opt);
  if (progress) progress->finish();
  if (!result) return fail(result.error().message);
  if (!a.quiet) std::fputs(format_track_summary(*result).c_str(), stdout);
  return 0;
}

void register_track(CLI::App& app, int& exit_code) {
  auto args = std::make_shared<TrackArgs>();
  CLI::App* cmd = app.add_subcommand(
      "track",
      "Track a recording offline: writes points.csv, poses.csv, markers.csv and (with --model) "
      "angles.csv");
  cmd->add_option("recording", args->recording,
                  "Recording folder (rig.yaml, frames.csv, cam0/, cam1/)")
      ->required();
  cmd->add_option("--targets", args->targets, "Marker targets (targets.yaml)")->required();
  cmd->add_option("--model", args->model,
                  "Calibrated joint model (model.yaml): enables angles.csv");
  cmd->add_option("--out", args->out, "Output folder")->required();
  cmd->add_option("--stats", args->stats, "Write per-stage latency statistics to this JSON file");
  cmd->add_option("--c3d", args->c3d,
                  "Also write the labelled marker trajectories as C3D (float, mm) to this file");
  cmd->add_option("--trc", args->trc,
                  "Also write the labelled marker trajectories as OpenSim TRC to this file");
  cmd->add_option("--truth", args->truth,
                  "Ground-truth folder of a simulated recording (REC/gt): print accuracy");
  cmd->add_option(
      "--config", args->config,
      "Take the detection/stereo/identification thresholds from this run configuration (YAML)");
  cmd->add_flag("--quiet", args->quiet, "Print nothing but errors and warnings");
  cmd->add_option("--threads", args->threads,
                  "Detection threads, 1 or 2 (default 2: the cameras of a frame are detected "
                  "on two cores, as live; the outputs are identical)")
      ->check(CLI::Range(1, 2));
  cmd->callback([args, &exit_code] { exit_code = run_track(*args); });
}

const CommandRegistrar kTrackRegistrar(20, register_track);

}  // namespace
}  // namespace mocap::app
