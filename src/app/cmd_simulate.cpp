// Design: `mocap simulate --out DIR [options]`: parses the flags with CLI11 and calls
// mocap::sim::write_simulated_recording (the library entry point); --scene picks the
// robot and its marker layout (the shoulder rig's limbs or stalks, or the humanoid),
// --cameras N renders through the built-in 2..8 cameras (the humanoid's ring 2..32), --rig
// through a user-given rig of 2..32 cameras. Errors are one line
// on stderr with exit code 2; success prints a one-line summary on stdout.
#include <cstdio>
#include <string>

#include "app/command_registry.h"
#include "app/progress.h"
#include "sim/scene_cameras.h"
#include "sim/simulate.h"
#include "sim/wand_sim.h"

namespace mocap::app {
namespace {

void register_simulate(CLI::App& app, int& exit_code) {
  struct Args {
    std::string out;
    std::string motion = "smooth";
    std::string scene = "limbs";
    sim::SimOptions opt;
    std::uint64_t seed = 1;
    bool noise_given = false;
    bool cameras_given = false;
  };
  auto args = std::make_shared<Args>();
  CLI::App* cmd = app.add_subcommand(
      "simulate",
      "Write a synthetic recording (2..32 cameras) of the shoulder test rig or the humanoid "
      "with ground truth");
  cmd->add_option("--out", args->out, "Output folder (created if needed)")->required();
  cmd->add_option("--frames", args->opt.frames, "Number of frames (default 100)");
  cmd->add_option("--scene", args->scene,
                  "Robot and marker layout: limbs (the shoulder rig, markers all around the "
                  "limbs) | stalks (its stress variant) | humanoid (the whole-body robot, 15 "
                  "bodies) (default limbs)");
  cmd->add_option("--rig", args->opt.rig_path,
                  "Render through this rig.yaml (2..32 cameras) instead of the built-in cameras");
  cmd->add_option_function<int>(
      "--cameras",
      [args](const int& n) {
        args->opt.cameras = n;
        args->cameras_given = true;
      },
      "Built-in cameras: 2 = the stereo pair, 3..8 on an arc around the robot (humanoid: "
      "2..32 on a ring all around it) (default 2, humanoid 8; with --rig: the rig's count)");
  cmd->add_option(
      "--motion", args->motion,
      "smooth | poses | move400 | viewpoints | explore | wand | lframe (default smooth)");
  cmd->add_option("--seed", args->seed, "Random seed of noise, drop-outs and strays (default 1)");
  cmd->add_option_function<double>(
      "--noise",
      [args](const double& v) {
        args->opt.noise_dn = v;
        args->noise_given = true;
      },
      "Read noise sigma in output DN (default 1.5 at 8 bits, scaled for 16 bits)");
  cmd->add_option("--blur", args->opt.blur_px,
                  "Optical blur (Gaussian PSF) sigma in px (default 0.5)");
  cmd->add_option("--stray", args->opt.stray, "Number of shiny spots causing glints (default 0)");
  cmd->add_flag("--streak", args->opt.streak,
                "Add a bright elongated reflection along the lower arm");
  cmd->add_option("--dropout", args->opt.dropout,
                  "Probability that a marker is missing in a camera's frame (default 0)");
  cmd->add_option("--bits", args->opt.bits, "8 or 16 (default 8)");
  cmd->add_option("--maxval", args->opt.maxval, "16-bit maxval, 256..65535 (default 4095)");
  cmd->add_option("--fps", args->opt.fps, "Frame rate for the timestamps (default 100)");
  cmd->add_option("--poses", args->opt.poses,
                  "Number of static poses of --motion poses (default 22)");
  cmd->add_option("--threads", args->opt.threads, "Rendering threads, 1 or 2 (default 2)");
  cmd->callback([args, &exit_code]() {
    auto scene = sim::parse_scene(args->scene);
    if (!scene) {
      exit_code = fail(scene.error().message);
      return;
    }
    args->opt.scene = *scene;
    const int max_cameras =
        *scene == sim::SceneKind::kHumanoid ? sim::kMaxSimCameras : sim::kMaxArcCameras;
    if (args->cameras_given && (args->opt.cameras < 2 || args->opt.cameras > max_cameras)) {
      exit_code = fail("simulate: cameras: must be 2.." + std::to_string(max_cameras) +
                       " for scene " + args->scene + ", got " + std::to_string(args->opt.cameras));
      return;
    }
    if (args->motion == "wand" || args->motion == "lframe") {  // rig calibration recordings
      args->opt.seed = args->seed;
      ProgressBar bar("simulate", args->opt.frames);
      auto r = sim::write_calibration_recording(
          args->opt,
          args->motion == "wand" ? sim::CalibObjectKind::kWand : sim::CalibObjectKind::kLFrame,
          args->out, [&bar](int done) { bar.update(done); });
      bar.finish();
      if (!r) {
        exit_code = fail(r.error().message);
        return;
      }
      std::printf(
          "simulate: wrote %d frames x %d cameras (%s) to %s in %.2f s: %lld isolated, "
          "%lld occluded, %lld dropped marker views, %lld glints\n",
          r->frames, r->cameras, args->motion.c_str(), args->out.c_str(), r->seconds,
          static_cast<long long>(r->isolated_views), static_cast<long long>(r->occluded_views),
          static_cast<long long>(r->dropped_views), static_cast<long long>(r->stray_blobs));
      exit_code = 0;
      return;
    }
    auto motion = sim::parse_motion(args->motion);
    if (!motion) {
      exit_code = fail(motion.error().message);
      return;
    }
    if (args->opt.noise_dn < 0.0 && args->noise_given) {
      exit_code = fail("simulate: noise: must be >= 0");
      return;
    }
    args->opt.motion = *motion;
    args->opt.seed = args->seed;
    ProgressBar bar("simulate", args->opt.frames);
    auto r = sim::write_simulated_recording(args->opt, args->out,
                                            [&bar](int done) { bar.update(done); });
    bar.finish();
    if (!r) {
      exit_code = fail(r.error().message);
      return;
    }
    std::printf(
        "simulate: wrote %d frames x %d cameras (%s, scene %s) to %s in %.2f s: %lld "
        "isolated, %lld occluded, %lld dropped marker views, %lld glints\n",
        r->frames, r->cameras, sim::motion_name(args->opt.motion), sim::scene_name(args->opt.scene),
        args->out.c_str(), r->seconds, static_cast<long long>(r->isolated_views),
        static_cast<long long>(r->occluded_views), static_cast<long long>(r->dropped_views),
        static_cast<long long>(r->stray_blobs));
    exit_code = 0;
  });
}

const CommandRegistrar registrar(10, register_simulate);

}  // namespace
}  // namespace mocap::app
