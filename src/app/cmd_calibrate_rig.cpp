// Design: `mocap calibrate-rig [WAND_REC] --wand wand.yaml --out rig.yaml
// [--intrinsics FILE [--intrinsics FILE]] [--lframe LFRAME_REC] [--report DIR]
// [--intrinsics-mode auto|refine|fixed] [--min-frames N]`: the wand calibration of
// src/rigcal (docs/rig_calibration.md) for the 2 to 32 cameras of the recording's
// rig.yaml. Intrinsics come from the --intrinsics files (rig.yaml, OpenCV FileStorage
// YAML, ROS camera_info YAML: one file with all cameras or one per camera) or else
// from the recording's rig.yaml. Without a wand
// recording the command only imports: the files must then also give the pair's
// relative pose (cv::stereoCalibrate's R, T or a ROS left/right pair), and rig.yaml
// is written from them. Errors are one line on stderr (exit 2); warnings on stderr.
#include <cstdio>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "app/command_registry.h"
#include "formats/intrinsics_import.h"
#include "formats/recording.h"
#include "formats/rig_yaml.h"
#include "formats/wand_yaml.h"
#include "rigcal/report.h"
#include "rigcal/rig_calibrator.h"

namespace mocap::app {
namespace {

struct RigArgs {
  std::string recording, wand, out, lframe, report, mode = "auto";
  std::vector<std::string> intrinsics;
  int min_frames = 30;
  double rod_cut_deg = 0.0;  // 0: chosen from the recording
};

// The cameras' intrinsics (and maybe a pair's relative pose) from the --intrinsics
// files: one file with (at least) all n cameras, or one file per camera.
Expected<ImportedIntrinsics> load_intrinsics(const std::vector<std::string>& files, std::size_t n) {
  if (files.size() != 1 && files.size() != n)
    return make_error("calibrate-rig", "--intrinsics",
                      n == 2 ? std::string("give one file (both cameras) or two")
                             : "give one file (all " + std::to_string(n) +
                                   " cameras) or one per camera (" + std::to_string(n) + ")");
  if (files.size() == 2 && n == 2) {
    auto a = import_intrinsics(files[0]);
    if (!a) return a.error();
    auto b = import_intrinsics(files[1]);
    if (!b) return b.error();
    if (a->cameras.size() != 1 || b->cameras.size() != 1)
      return make_error(a->cameras.size() != 1 ? files[0] : files[1], "cameras",
                        "with two --intrinsics files, each must describe one camera");
    if (a->format == IntrinsicsFormat::kRosCameraInfo &&
        b->format == IntrinsicsFormat::kRosCameraInfo) {
      auto pair = import_ros_stereo(files[0], files[1]);
      if (pair) return pair;  // without rectification data: intrinsics only
    }
    ImportedIntrinsics out = *a;
    out.cameras.push_back(b->cameras[0]);
    if (out.cameras[0].name == out.cameras[1].name) {
      out.cameras[0].name = "cam0";
      out.cameras[1].name = "cam1";
    }
    return out;
  }
  if (files.size() > 1) {
    ImportedIntrinsics out;
    for (const std::string& file : files) {
      auto one = import_intrinsics(file);
      if (!one) return one.error();
      if (one->cameras.size() != 1)
        return make_error(file, "cameras",
                          "with one --intrinsics file per camera, each must describe one camera");
      out.cameras.push_back(one->cameras[0]);
    }
    return out;
  }
  auto a = import_intrinsics(files[0]);
  if (!a) return a.error();
  if (a->cameras.size() < n)
    return make_error(files[0], "cameras",
                      n == 2 ? std::string("describes one camera: give a second --intrinsics "
                                           "file for camera 1")
                             : "describes " + std::to_string(a->cameras.size()) +
                                   " cameras, the recording has " + std::to_string(n));
  a->cameras.resize(n);
  return a;
}

int import_only(const RigArgs& a) {
  if (a.intrinsics.empty())
    return fail("calibrate-rig: give a wand recording, or --intrinsics files to import");
  auto imp = load_intrinsics(a.intrinsics, 2);
  if (!imp) return fail(imp.error().message);
  if (!imp->has_relative_pose)
    return fail(a.intrinsics[0] +
                ": R, T: missing: importing without a wand recording needs the pair's relative "
                "pose (cv::stereoCalibrate's R and T, or a ROS left/right pair)");
  Rig rig;
  rig.cameras = {imp->cameras[0], imp->cameras[1]};
  for (const CameraModel& c : rig.cameras) {
    if (c.width <= 0 || c.height <= 0)
      return fail(a.intrinsics[0] +
                  ": image_width: missing: the image size is needed for "
                  "rig.yaml (add image_width and image_height)");
  }
  rig.cameras[1].R_cam_world = imp->R_1_0;
  rig.cameras[1].t_cam_world = imp->t_1_0_mm;
  if (auto r = save_rig(a.out, rig); !r) return fail(r.error().message);
  std::printf("calibrate-rig: imported %s -> %s (baseline %.3f mm)\n", a.intrinsics[0].c_str(),
              a.out.c_str(), imp->t_1_0_mm.norm());
  return 0;
}

int run(const RigArgs& a) {
  if (a.recording.empty()) return import_only(a);
  if (a.wand.empty()) return fail("calibrate-rig: --wand: required with a wand recording");
  rigcal::RigCalOptions opt;
  opt.min_frames = a.min_frames;
  opt.rod_cut_deg = a.rod_cut_deg;
  if (a.mode == "auto") {
    opt.intrinsics = rigcal::IntrinsicsMode::kAuto;
  } else if (a.mode == "refine") {
    opt.intrinsics = rigcal::IntrinsicsMode::kRefine;
  } else if (a.mode == "fixed") {
    opt.intrinsics = rigcal::IntrinsicsMode::kFixed;
  } else {
    return fail("calibrate-rig: --intrinsics-mode: must be auto, refine or fixed, got '" + a.mode +
                "'");
  }
  if (a.min_frames < 8) return fail("calibrate-rig: --min-frames: must be >= 8");
  if (a.rod_cut_deg != 0.0 && !(a.rod_cut_deg >= rigcal::kRodCutsDeg.front() &&
                                a.rod_cut_deg <= rigcal::kRodCutsDeg.back()))
    return fail(
        "calibrate-rig: --rod-cut: must be 20 to 60 degrees (or 0: chosen from the "
        "recording), got " +
        std::to_string(a.rod_cut_deg));
  auto objects = load_calibration_objects(a.wand);
  if (!objects) return fail(objects.error().message);
  if (!a.lframe.empty() && !objects->has_lframe)
    return fail(a.wand +
                ": lframe: missing: --lframe needs the L-frame's markers in the wand file");
  auto rec = Recording::open(a.recording);
  if (!rec) return fail(rec.error().message);
  const std::size_t ncams = rec->rig().cameras.size();
  if (auto v = rigcal::check_camera_count(ncams, a.recording); !v) return fail(v.error().message);
  std::vector<CameraModel> intr = rec->rig().cameras;
  if (!a.intrinsics.empty()) {
    auto imp = load_intrinsics(a.intrinsics, ncams);
    if (!imp) return fail(imp.error().message);
    for (std::size_t c = 0; c < ncams; ++c) {
      CameraModel m = imp->cameras[c];
      const CameraModel& r = rec->rig().cameras[c];
      if (m.width == 0 && m.height == 0) {
        m.width = r.width;
        m.height = r.height;
      }
      if (m.width != r.width || m.height != r.height)
        return fail(a.intrinsics[std::min(c, a.intrinsics.size() - 1)] + ": image size " +
                    std::to_string(m.width) + "x" + std::to_string(m.height) +
                    " differs from the recording's " + r.name + " (" + std::to_string(r.width) +
                    "x" + std::to_string(r.height) + ")");
      m.name = r.name;  // the recording's folder names
      intr[c] = m;
    }
  }
  auto detected = rigcal::detect_recording(a.recording, opt, &intr, &objects->wand);
  if (!detected) return fail(detected.error().message);
  for (const std::string& n : detected->notes)
    std::fprintf(stderr, "mocap calibrate-rig: note: %s\n", n.c_str());
  auto result = rigcal::calibrate_from_blobs(detected->blobs, objects->wand, intr, opt, a.recording,
                                             &detected->info);
  if (!result) return fail(result.error().message);
  result->wand_centres = detected->rod_cut;
  result->wand_centres_partly_hidden = detected->rod_cut_partly_hidden;
  if (!a.lframe.empty()) {
    auto lb = rigcal::detect_recording(a.lframe, opt, &intr);
    if (!lb) return fail(lb.error().message);
    for (const std::string& n : lb->notes)
      std::fprintf(stderr, "mocap calibrate-rig: note: %s\n", n.c_str());
    if (auto r = rigcal::set_ground_frame(*result, lb->blobs, objects->lframe, opt, a.lframe); !r)
      return fail(r.error().message);
  }
  Rig rig;
  rig.cameras = result->cameras;
  if (auto r = save_rig(a.out, rig); !r) return fail(r.error().message);
  std::string report = a.report;
  if (report.empty()) {
    std::filesystem::path p(a.out);
    report = (p.parent_path() / (p.stem().string() + "_report")).string();
  }
  if (auto r = rigcal::write_report(report, *result, opt); !r) return fail(r.error().message);
  for (const std::string& w : result->warnings)
    std::fprintf(stderr, "mocap: warning: %s\n", w.c_str());
  std::string rms;
  for (const rigcal::CameraQuality& q : result->quality) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%s%.3f", rms.empty() ? "" : " / ", q.reprojection_rms_px);
    rms += buf;
  }
  std::printf(
      "calibrate-rig: %d of %d frames used, baseline %.3f mm, reprojection RMS %s px, wand "
      "length error mean %.4f mm RMS %.4f mm%s -> %s (report in %s)\n",
      result->frames_used, result->frames_total, result->baseline_mm, rms.c_str(),
      result->wand_length_mean_error_mm, result->wand_length_rms_error_mm,
      result->has_ground ? ", ground frame set" : "", a.out.c_str(), report.c_str());
  std::printf("calibrate-rig: %s\n", result->intrinsics_note.c_str());
  return 0;
}

void register_calibrate_rig(CLI::App& app, int& exit_code) {
  auto args = std::make_shared<RigArgs>();
  CLI::App* cmd = app.add_subcommand(
      "calibrate-rig",
      "Calibrate the camera rig (2 to 32 cameras) from a wand recording (and an L-frame), or "
      "import intrinsics into rig.yaml");
  cmd->add_option("recording", args->recording, "Wand recording folder");
  cmd->add_option("--wand", args->wand, "Wand (and L-frame) description, wand.yaml");
  cmd->add_option("--out", args->out, "Output rig.yaml")->required();
  cmd->add_option("--intrinsics", args->intrinsics,
                  "rig.yaml, OpenCV FileStorage YAML or ROS camera_info YAML (once for all "
                  "cameras, or once per camera in rig.yaml's order); default: the recording's "
                  "rig.yaml");
  cmd->add_option("--lframe", args->lframe, "L-frame recording folder: sets the world frame");
  cmd->add_option("--report", args->report,
                  "Folder of report.yaml and the coverage PNGs (default: <out>_report)");
  cmd->add_option("--intrinsics-mode", args->mode,
                  "auto (refine when the wand covered the images well), refine or fixed");
  cmd->add_option("--min-frames", args->min_frames,
                  "Fewest frames with the wand in two or more cameras (default 30)");
  cmd->add_option("--rod-cut", args->rod_cut_deg,
                  "Degrees of each wand ball's rim left out beside the rod (20..60, taken to "
                  "the nearest 5); default: chosen from the recording");
  cmd->callback([args, &exit_code] { exit_code = run(*args); });
}

const CommandRegistrar kCalibrateRigRegistrar(35, register_calibrate_rig);

}  // namespace
}  // namespace mocap::app
