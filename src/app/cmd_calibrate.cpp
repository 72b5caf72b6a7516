// `mocap calibrate REC --targets targets.yaml --joints joints.yaml --out model.yaml
// [--urdf robot.urdf]`: tracks the recording (src/track), estimates every joint of
// joints.yaml (src/kinematics: Eq. 2 ball joints, rank-5 hinges, Ceres refinement of
// the chain) and writes model.yaml, optionally a URDF, and prints a short report.
#include <cstdio>
#include <memory>
#include <string>

#include "app/command_registry.h"
#include "app/progress.h"
#include "formats/joints_yaml.h"
#include "formats/targets_yaml.h"
#include "kinematics/calibrate.h"
#include "kinematics/urdf_writer.h"
#include "track/calibration_input.h"

namespace mocap::app {
namespace {

struct CalibrateArgs {
  std::string recording, targets, joints, out, urdf;
  bool no_refine = false;
  bool quiet = false;
};

int run_calibrate(const CalibrateArgs& a) {
  auto targets = load_targets(a.targets);
  if (!targets) return fail(targets.error().message);
  auto topology = load_joints(a.joints, *targets);
  if (!topology) return fail(topology.error().message);

  CalibrationCollectOptions opt;
  std::unique_ptr<ProgressBar> progress;
  opt.progress = [&](std::int64_t done, std::int64_t total) {
    if (!progress) progress = std::make_unique<ProgressBar>("calibrate: tracking", total);
    progress->update(done);
  };
  opt.warn = [&](const std::string& m) {
    if (progress) progress->finish();
    std::fprintf(stderr, "mocap: warning: %s\n", m.c_str());
  };
  auto collected = collect_calibration_input(a.recording, *targets, opt);
  if (progress) progress->finish();
  if (!collected) return fail(collected.error().message);

  kinematics::CalibrationOptions copt;
  copt.refine = !a.no_refine;
  copt.covariance = !a.no_refine;
  auto result = kinematics::calibrate_joints(*targets, *topology, collected->input, copt);
  if (!result) return fail(a.recording + ": " + result.error().message);
  for (const std::string& w : result->report.warnings)
    std::fprintf(stderr, "mocap: warning: %s\n", w.c_str());
  if (auto r = save_model(a.out, result->model); !r) return fail(r.error().message);
  if (!a.urdf.empty()) {
    auto r = kinematics::write_urdf(a.urdf, result->model, "mocap_robot", targets->bodies.size());
    if (!r) return fail(r.error().message);
  }
  if (!a.quiet) {
    std::printf("calibrated %zu joints from %lld frames (%lld with every body found) -> %s\n",
                result->model.joints.size(), static_cast<long long>(collected->frames),
                static_cast<long long>(collected->frames_all_bodies), a.out.c_str());
    std::fputs(kinematics::format_report(*result).c_str(), stdout);
  }
  return 0;
}

void register_calibrate(CLI::App& app, int& exit_code) {
  auto args = std::make_shared<CalibrateArgs>();
  CLI::App* cmd = app.add_subcommand(
      "calibrate", "Estimate the kinematic model (ball and hinge joints) from a recording");
  cmd->add_option("recording", args->recording,
                  "Recording folder of the joints moving through distinct poses")
      ->required();
  cmd->add_option("--targets", args->targets, "Marker targets (targets.yaml)")->required();
  cmd->add_option("--joints", args->joints, "Joint topology (joints.yaml)")->required();
  cmd->add_option("--out", args->out, "Output model (model.yaml)")->required();
  cmd->add_option("--urdf", args->urdf, "Also write a URDF of the chain");
  cmd->add_flag("--no-refine", args->no_refine,
                "Linear estimates only (no Ceres refinement, no uncertainty)");
  cmd->add_flag("--quiet", args->quiet, "Print nothing but errors and warnings");
  cmd->callback([args, &exit_code] { exit_code = run_calibrate(*args); });
}

const CommandRegistrar kCalibrateRegistrar(30, register_calibrate);

}  // namespace
}  // namespace mocap::app
