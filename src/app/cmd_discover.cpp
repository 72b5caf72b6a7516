// `mocap discover REC --out DIR [--urdf FILE]`: finds the marker targets, the joint
// topology and the calibrated model from a recording of the robot moving its joints
// (src/discover; docs/discover.md) and writes DIR/targets.yaml, DIR/joints.yaml and
// DIR/model.yaml (and a URDF), with warnings for every doubt and a short report.
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <string>

#include "app/command_registry.h"
#include "app/progress.h"
#include "discover/discover.h"
#include "discover/frame_points.h"
#include "formats/joints_yaml.h"
#include "formats/targets_yaml.h"
#include "kinematics/urdf_writer.h"

namespace mocap::app {
namespace {

struct DiscoverArgs {
  std::string recording, out, urdf;
  double max_speed_mm_per_s = discover::DiscoverOptions{}.max_speed_mm_per_s;
  double point_noise_mm = discover::DiscoverOptions{}.point_noise_mm;
  bool no_refine = false;
  bool stats = false;
  bool quiet = false;
};

int run_discover(const DiscoverArgs& a) {
  const auto t0 = std::chrono::steady_clock::now();
  discover::DiscoverOptions opt;
  opt.max_speed_mm_per_s = a.max_speed_mm_per_s;
  opt.point_noise_mm = a.point_noise_mm;
  opt.refine = !a.no_refine;
  if (!(opt.max_speed_mm_per_s > 0.0)) return fail("discover: --max-speed: must be > 0");
  if (!(opt.point_noise_mm >= 0.0))
    return fail("discover: --point-noise: must be > 0 (or 0: estimated from the recording)");

  std::unique_ptr<ProgressBar> progress;
  discover::PointsProgress cb;
  cb.progress = [&](std::int64_t done, std::int64_t total) {
    if (!progress) progress = std::make_unique<ProgressBar>("discover: triangulating", total);
    progress->update(done);
  };
  cb.warn = [&](const std::string& m) {
    if (progress) progress->finish();
    std::fprintf(stderr, "mocap: warning: %s\n", m.c_str());
  };
  auto points = discover::triangulate_recording(a.recording, cb);
  if (progress) progress->finish();
  if (!points) return fail(points.error().message);
  const double seconds_points =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();

  std::unique_ptr<ProgressBar> tracking;
  auto result = discover::discover_model(
      *points, opt, a.recording,
      discover::tracker_poses(a.recording, [&](std::int64_t done, std::int64_t total) {
        if (!tracking) tracking = std::make_unique<ProgressBar>("discover: tracking", total);
        tracking->update(done);
      }));
  if (tracking) tracking->finish();
  if (!result) return fail(result.error().message);
  for (const std::string& w : result->warnings)
    std::fprintf(stderr, "mocap: warning: %s\n", w.c_str());

  std::error_code ec;
  std::filesystem::create_directories(a.out, ec);
  if (ec) return fail(a.out + ": cannot create directory: " + ec.message());
  if (auto r = save_targets(a.out + "/targets.yaml", result->targets); !r)
    return fail(r.error().message);
  if (result->topology.joints.empty())  // joints.yaml must list a joint (spec): stop here
    return fail(a.recording + ": no joint found between the " +
                std::to_string(result->targets.bodies.size()) + " bodies (only " + a.out +
                "/targets.yaml written)");
  if (auto r = save_model(a.out + "/joints.yaml", result->topology); !r)
    return fail(r.error().message);
  if (auto r = save_model(a.out + "/model.yaml", result->model); !r) return fail(r.error().message);
  if (!a.urdf.empty()) {
    auto r =
        kinematics::write_urdf(a.urdf, result->model, "mocap_robot", result->targets.bodies.size());
    if (!r) return fail(r.error().message);
  }
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  if (!a.quiet) {
    std::printf("discovered %zu bodies and %zu joints from %d frames -> %s\n",
                result->targets.bodies.size(), result->model.joints.size(), result->stats.frames,
                a.out.c_str());
    for (const MarkerTarget& b : result->targets.bodies)
      std::printf("  %s: %zu markers\n", b.name.c_str(), b.markers_body.size());
    for (const JointSpec& j : result->topology.joints)
      std::printf("  %s: %s, %s -> %s\n", j.name.c_str(), joint_type_name(j.type), j.parent.c_str(),
                  j.child.c_str());
    if (!result->model.joints.empty())
      std::fputs(kinematics::format_report(result->calibration).c_str(), stdout);
  }
  if (a.stats) {
    const discover::DiscoverStats& s = result->stats;
    std::printf(
        "stats: frames %d, points %lld, point noise %.3f mm, tracks %d (%d long), clusters %d, "
        "unplaced %d; seconds: triangulate %.2f, track %.2f, group %.2f, bodies %.2f, tracker "
        "%.2f, topology %.2f, calibrate %.2f, total %.2f\n",
        s.frames, s.points, s.point_noise_mm, s.tracks, s.long_tracks, s.clusters,
        s.unplaced_tracks, seconds_points, s.seconds_tracking, s.seconds_grouping, s.seconds_bodies,
        s.seconds_tracker, s.seconds_topology, s.seconds_calibration, seconds);
  }
  return 0;
}

void register_discover(CLI::App& app, int& exit_code) {
  auto args = std::make_shared<DiscoverArgs>();
  CLI::App* cmd = app.add_subcommand(
      "discover",
      "Find marker targets, joints and the calibrated model from a recording of the robot moving");
  cmd->add_option("recording", args->recording, "Recording folder of the robot moving its joints")
      ->required();
  cmd->add_option("--out", args->out, "Output folder (targets.yaml, joints.yaml, model.yaml)")
      ->required();
  cmd->add_option("--urdf", args->urdf, "Also write a URDF of the discovered chain");
  cmd->add_option("--max-speed", args->max_speed_mm_per_s,
                  "Fastest marker speed, mm/s (tracking gates)");
  cmd->add_option("--point-noise", args->point_noise_mm,
                  "1-sigma noise of a 3D marker point, mm (rigidity tests); default "
                  "0: estimated from the recording's point tracks");
  cmd->add_flag("--no-refine", args->no_refine,
                "Linear joint estimates only (no Ceres refinement)");
  cmd->add_flag("--stats", args->stats, "Print counts and the time of every step");
  cmd->add_flag("--quiet", args->quiet, "Print nothing but errors and warnings");
  cmd->callback([args, &exit_code] { exit_code = run_discover(*args); });
}

const CommandRegistrar kDiscoverRegistrar(32, register_discover);

}  // namespace
}  // namespace mocap::app
