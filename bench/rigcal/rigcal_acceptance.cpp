// Design: the rig calibration's acceptance run (docs/rig_calibration.md). Simulates a
// wand recording (default 500 frames, 3 room glints, 2% drop-outs, default noise) and
// an L-frame recording, calibrates with the library exactly as `mocap calibrate-rig`
// does, and compares with the ground truth:
//  - baseline and relative rotation of the recovered pair vs the true rig;
//  - wand-length error (the report's figure);
//  - 3D accuracy on the same recording: every gt marker that is isolated in both
//    cameras is matched to its blob (nearest within 1.5 px of its true projection) and
//    triangulated with the true rig and with the calibrated rig (world = camera 0, so
//    the truth is mapped with the true T_cam0_world); RMS 3D error of both;
//  - ground frame: camera centres and rotations of the L-frame rig vs the truth.
//  - every camera's pose relative to camera 0 (position of its centre in camera 0's
//    frame, mm, and rotation, deg) against the truth: with 3..8 cameras (the simulator's
//    built-in ring) the acceptance figure of the N-camera calibration;
//  - per camera, the frames that labelled the wand, those used, and why the others did not.
// Usage: rigcal_acceptance [frames] [seed] [intrinsics: true|perturbed] [mode: auto|refine|fixed]
//                          [cameras: 2..8]
// Environment: RIGCAL_MIN_ROUNDNESS (the blob filter), RIGCAL_CENTRES = centroid | edge |
// axis (the wand balls' centres: intensity centroid, edge fit, edge fit without the rim
// along the wand's axis on the rod's side; default axis, as mocap calibrate-rig),
// RIGCAL_ROD_CUT = degrees (that cut instead of the one chosen from the recording),
// RIGCAL_SIM_BLUR = px, RIGCAL_SIM_NOISE = DN (the renderer's PSF sigma and read noise
// instead of the defaults: other lenses and sensors), RIGCAL_RIG = a rig.yaml rendered through
// instead of the built-in cameras (CAMERAS must be its camera count; e.g. docs/rigs/),
// RIGCAL_TRUTH_NOISE = sigma px (the wand centres replaced by their true projections plus Gaussian
// noise: the noise floor of the geometry and frame count), RIGCAL_WEIGHTS=0 (every centre weighs
// the same in the bundle adjustment). Each run renders into its own folder under $TMPDIR
// (rigcal_acceptance_<seed>_<cameras>).
#include <Eigen/Geometry>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "formats/rig_yaml.h"
#include "rigcal/rig_calibrator.h"
#include "sim/wand_sim.h"
#include "stereo/two_view.h"
#include "truth_markers.h"

using namespace mocap;

namespace {

double rot_deg(const Mat3& a, const Mat3& b) {
  return Eigen::AngleAxisd(a * b.transpose()).angle() * 180.0 / 3.14159265358979323846;
}

bool nearest(const std::vector<Vec2>& blobs, const Vec2& p, Vec2& out) {
  double best = 1.5;
  bool found = false;
  for (const Vec2& b : blobs) {
    if ((b - p).norm() < best) {
      best = (b - p).norm();
      out = b;
      found = true;
    }
  }
  return found;
}

}  // namespace

int main(int argc, char** argv) {
  const int frames = argc > 1 ? std::atoi(argv[1]) : 500;
  const auto seed = static_cast<std::uint64_t>(argc > 2 ? std::atoll(argv[2]) : 1);
  const std::string intr_mode = argc > 3 ? argv[3] : "true";
  const std::string mode = argc > 4 ? argv[4] : "auto";
  const int cameras = argc > 5 ? std::atoi(argv[5]) : 2;
  if (cameras < 2 || cameras > 8) {
    std::fprintf(stderr, "rigcal_acceptance: cameras must be 2..8, got %d\n", cameras);
    return 1;
  }
  const std::string dir =
      (std::filesystem::temp_directory_path() /
       ("rigcal_acceptance_" + std::to_string(seed) + "_" + std::to_string(cameras)))
          .string();
  std::filesystem::remove_all(dir);
  sim::SimOptions so;
  so.frames = frames;
  so.seed = seed;
  so.stray = 3;
  so.dropout = 0.02;
  if (const char* b = std::getenv("RIGCAL_SIM_BLUR")) so.blur_px = std::atof(b);
  if (const char* n = std::getenv("RIGCAL_SIM_NOISE")) so.noise_dn = std::atof(n);
  if (const char* r = std::getenv("RIGCAL_RIG")) so.rig_path = r;  // CAMERAS must be its count
  so.cameras = cameras;
  auto t0 = std::chrono::steady_clock::now();
  auto w = sim::write_calibration_recording(so, sim::CalibObjectKind::kWand, dir + "/wand");
  so.frames = 20;
  auto l = sim::write_calibration_recording(so, sim::CalibObjectKind::kLFrame, dir + "/lframe");
  if (!w || !l) {
    std::fprintf(stderr, "%s\n", (!w ? w.error() : l.error()).message.c_str());
    return 1;
  }
  auto t1 = std::chrono::steady_clock::now();
  auto truth = load_rig(dir + "/wand/gt/rig_true.yaml");
  auto truth_l = load_rig(dir + "/lframe/gt/rig_lframe_true.yaml");
  if (!truth || !truth_l) return 1;
  std::vector<CameraModel> intr = truth->cameras;
  if (intr_mode == "perturbed") {
    intr[0].fx *= 1.004;
    intr[0].fy *= 1.004;
    intr[0].cx += 3.0;
    intr[0].distortion[0] += 0.01;
    intr[1].fx *= 0.996;
    intr[1].fy *= 0.997;
    intr[1].cy -= 3.0;
    intr[1].distortion[1] -= 0.02;
  }
  rigcal::RigCalOptions opt;
  opt.intrinsics = mode == "refine"  ? rigcal::IntrinsicsMode::kRefine
                   : mode == "fixed" ? rigcal::IntrinsicsMode::kFixed
                                     : rigcal::IntrinsicsMode::kAuto;
  if (const char* r = std::getenv("RIGCAL_MIN_ROUNDNESS")) opt.min_roundness = std::atof(r);
  // RIGCAL_CENTRES=centroid | edge (no wand axis) | axis (default, as the command does).
  const std::string centres =
      std::getenv("RIGCAL_CENTRES") ? std::getenv("RIGCAL_CENTRES") : "axis";
  opt.edge_centres = centres != "centroid";
  const WandSpec wand = sim::default_calibration_objects().wand;
  if (const char* r = std::getenv("RIGCAL_ROD_CUT")) opt.rod_cut_deg = std::atof(r);
  auto detected =
      rigcal::detect_recording(dir + "/wand", opt, &intr, centres == "axis" ? &wand : nullptr);
  if (!detected) {
    std::fprintf(stderr, "%s\n", detected.error().message.c_str());
    return 1;
  }
  rigcal::FrameBlobs* blobs = &detected->blobs;
  // RIGCAL_TRUTH_NOISE=sigma: every detected wand centre is replaced by its true
  // projection plus Gaussian noise of sigma px per axis: what the geometry and the
  // frames allow with unbiased centres of that precision.
  if (const char* gn = std::getenv("RIGCAL_TRUTH_NOISE")) {
    const double sg = std::atof(gn);
    std::mt19937 rng(7);
    std::normal_distribution<double> nd(0.0, sg);
    for (const bench::TruthMarker& m :
         bench::read_truth_markers(dir + "/wand/gt/markers.csv", cameras)) {
      const auto fi = static_cast<std::size_t>(m.frame);
      if (fi >= blobs->size()) continue;
      for (std::size_t c = 0; c < m.px.size(); ++c) {
        for (Vec2& b : (*blobs)[fi][c])
          if ((b - m.px[c]).norm() < 1.5) b = m.px[c] + Vec2(nd(rng), nd(rng));
      }
    }
  }
  auto t2 = std::chrono::steady_clock::now();
  // RIGCAL_WEIGHTS=0: every centre weighs the same (the truth-noise centres always do).
  if (const char* wt = std::getenv("RIGCAL_WEIGHTS")) opt.weight_centres = std::atoi(wt) != 0;
  auto res =
      rigcal::calibrate_from_blobs(*blobs, wand, intr, opt, dir + "/wand",
                                   std::getenv("RIGCAL_TRUTH_NOISE") ? nullptr : &detected->info);
  if (!res) {
    std::fprintf(stderr, "%s\n", res.error().message.c_str());
    return 1;
  }
  auto t3 = std::chrono::steady_clock::now();
  const std::vector<CameraModel> cal = res->cameras;  // world = camera 0
  // Relative pose errors.
  const Iso3 T10_true = truth->cameras[1].T_cam_world() * truth->cameras[0].T_cam_world().inverse();
  const Iso3 T10_cal = cal[1].T_cam_world() * cal[0].T_cam_world().inverse();
  const double base_true = T10_true.translation().norm(), base_cal = T10_cal.translation().norm();
  const double rot_err = rot_deg(T10_cal.linear(), T10_true.linear());
  const double dir_err =
      std::acos(std::min(
          1.0, T10_cal.translation().normalized().dot(T10_true.translation().normalized()))) *
      180.0 / 3.14159265358979323846;
  // 3D accuracy on the same recording.
  const auto gt = bench::read_truth_markers(dir + "/wand/gt/markers.csv", cameras);
  auto g_true = make_stereo_geometry(truth->cameras[0], truth->cameras[1]);
  auto g_cal = make_stereo_geometry(cal[0], cal[1]);
  if (!g_true || !g_cal) return 1;
  const Iso3 T_cam0_world = truth->cameras[0].T_cam_world();
  double ss_true = 0.0, ss_cal = 0.0;
  int n = 0;
  std::vector<Vec3> pts_cal, pts_gt;
  for (const bench::TruthMarker& m : gt) {
    if (!m.alone[0] || !m.alone[1] || m.frame >= static_cast<int>(blobs->size())) continue;
    Vec2 b0, b1;
    const auto& fb = (*blobs)[static_cast<std::size_t>(m.frame)];
    if (!nearest(fb[0], m.px[0], b0) || !nearest(fb[1], m.px[1], b1)) continue;
    Vec3 Xt, Xc;
    double r0, r1;
    if (!triangulate_pixels(*g_true, truth->cameras[0], truth->cameras[1], b0, b1, Xt, r0))
      continue;
    if (!triangulate_pixels(*g_cal, cal[0], cal[1], b0, b1, Xc, r1)) continue;
    ss_true += (Xt - m.X).squaredNorm();
    ss_cal += (Xc - T_cam0_world * m.X).squaredNorm();
    pts_cal.push_back(Xc);
    pts_gt.push_back(m.X);
    ++n;
  }
  // The calibrated reconstruction aligned rigidly to the truth (the world frame is a
  // gauge choice): the acceptance figure.
  Eigen::Matrix3Xd A(3, n), B(3, n);
  for (int i = 0; i < n; ++i) {
    A.col(i) = pts_cal[static_cast<std::size_t>(i)];
    B.col(i) = pts_gt[static_cast<std::size_t>(i)];
  }
  const Eigen::Matrix4d T_align = Eigen::umeyama(A, B, false);
  double ss_aligned = 0.0;
  for (int i = 0; i < n; ++i) {
    const Vec3 p = T_align.topLeftCorner<3, 3>() * A.col(i) + T_align.topRightCorner<3, 1>();
    ss_aligned += (p - B.col(i)).squaredNorm();
  }
  const double rms_aligned = std::sqrt(ss_aligned / std::max(1, n));
  // Wand-length error with the true rig on the same frames (the floor set by detection).
  double wl_ss = 0.0;
  int wl_n = 0;
  {
    std::vector<Vec3> ends;
    int last_frame = -1;
    for (const bench::TruthMarker& m : gt) {
      if (m.frame != last_frame) ends.clear();
      last_frame = m.frame;
      Vec2 b0, b1;
      const auto& fb = (*blobs)[static_cast<std::size_t>(m.frame)];
      Vec3 X;
      double r0;
      if (nearest(fb[0], m.px[0], b0) && nearest(fb[1], m.px[1], b1) &&
          triangulate_pixels(*g_true, truth->cameras[0], truth->cameras[1], b0, b1, X, r0)) {
        ends.push_back(X);
      } else {
        ends.push_back(Vec3::Constant(1e9));
      }
      if (ends.size() == 3 && ends[0].x() < 1e8 && ends[2].x() < 1e8) {
        const double e = (ends[2] - ends[0]).norm() - 300.0;
        wl_ss += e * e;
        ++wl_n;
      }
    }
  }
  const double rms_true = std::sqrt(ss_true / std::max(1, n));
  const double rms_cal = std::sqrt(ss_cal / std::max(1, n));
  // Ground frame.
  auto lb = rigcal::detect_recording(dir + "/lframe", opt, &intr);
  if (!lb) return 1;
  rigcal::RigCalResult with_ground = *res;
  if (auto r = rigcal::set_ground_frame(
          with_ground, lb->blobs, sim::default_calibration_objects().lframe, opt, dir + "/lframe");
      !r) {
    std::fprintf(stderr, "%s\n", r.error().message.c_str());
    return 1;
  }
  double ground_pos = 0.0, ground_rot = 0.0;
  for (std::size_t c = 0; c < intr.size(); ++c) {
    ground_pos = std::max(
        ground_pos,
        (with_ground.cameras[c].center_world() - truth_l->cameras[c].center_world()).norm());
    ground_rot = std::max(
        ground_rot, rot_deg(with_ground.cameras[c].R_cam_world, truth_l->cameras[c].R_cam_world));
  }
  auto sec = [](auto a, auto b) { return std::chrono::duration<double>(b - a).count(); };
  std::printf("frames %d seed %llu intrinsics %s mode %s cameras %d centres %s\n", frames,
              static_cast<unsigned long long>(seed), intr_mode.c_str(), mode.c_str(), cameras,
              centres.c_str());
  for (const rigcal::RodCutChoice* cut : {&detected->rod_cut, &detected->rod_cut_partly_hidden}) {
    const rigcal::RodCutChoice& rc = *cut;
    std::printf(
        "  wand centres%s: rod-side cut %.0f deg (%s), %d end-ball views, outer rim used in "
        "%.0f %%; per cut: mean shift away from the rod (its standard error) / along-wand noise, "
        "px:",
        cut == &detected->rod_cut ? "" : " (partly hidden)", rc.cut_deg,
        rc.from_recording ? "chosen" : "fixed", rc.end_ball_views, 100.0 * rc.outer_rim_used);
    for (std::size_t j = 0; j < rigcal::kRodCutsDeg.size(); ++j)
      std::printf(" %.0f:%+.4f(%.4f)/%.3f", rigcal::kRodCutsDeg[j], rc.mean_shift_px[j],
                  rc.standard_error_px[j], rc.along_sd_px[j]);
    std::printf("\n");
  }
  std::printf("  frames: wand in both %d, used %d; intrinsics refined: %s\n", res->frames_both,
              res->frames_used, res->intrinsics_refined ? "yes" : "no");
  std::printf(
      "  baseline error %.4f mm (true %.3f mm), rotation error %.5f deg, baseline "
      "direction error %.5f deg\n",
      base_cal - base_true, base_true, rot_err, dir_err);
  std::printf("  reprojection RMS %.4f / %.4f px; wand length error mean %.4f mm RMS %.4f mm\n",
              res->quality[0].reprojection_rms_px, res->quality[1].reprojection_rms_px,
              res->wand_length_mean_error_mm, res->wand_length_rms_error_mm);
  if (intr_mode == "perturbed") {
    for (std::size_t c = 0; c < 2; ++c) {
      std::printf("  %s: fx err %.3f px, fy %.3f, cx %.3f, cy %.3f, k1 %.5f, k2 %.5f\n",
                  cal[c].name.c_str(), cal[c].fx - truth->cameras[c].fx,
                  cal[c].fy - truth->cameras[c].fy, cal[c].cx - truth->cameras[c].cx,
                  cal[c].cy - truth->cameras[c].cy,
                  cal[c].distortion[0] - truth->cameras[c].distortion[0],
                  cal[c].distortion[1] - truth->cameras[c].distortion[1]);
    }
  }
  // Every camera's pose relative to camera 0.
  double worst_mm = 0.0, worst_deg = 0.0;
  for (std::size_t c = 1; c < cal.size(); ++c) {
    const Iso3 T_c0_true =
        truth->cameras[c].T_cam_world() * truth->cameras[0].T_cam_world().inverse();
    const Iso3 T_c0_cal = cal[c].T_cam_world() * cal[0].T_cam_world().inverse();
    const Vec3 C_true = T_c0_true.inverse().translation(), C_cal = T_c0_cal.inverse().translation();
    const double pos_mm = (C_cal - C_true).norm();
    const double along_mm = (C_cal - C_true).dot(C_true.normalized());
    const double deg = rot_deg(T_c0_cal.linear(), T_c0_true.linear());
    worst_mm = std::max(worst_mm, pos_mm);
    worst_deg = std::max(worst_deg, deg);
    std::printf(
        "  %s relative to %s: position error %.4f mm (along the baseline %+.4f mm, "
        "baseline %.0f mm), rotation error %.5f deg, reprojection RMS %.4f px\n",
        cal[c].name.c_str(), cal[0].name.c_str(), pos_mm, along_mm, C_true.norm(), deg,
        res->quality[c].reprojection_rms_px);
  }
  for (std::size_t c = 0; c < cal.size(); ++c) {
    const auto& q = res->quality[c];
    std::printf(
        "  %s: labelled %d, used %d; rejected: too few blobs %d, too many %d, no wand %d, "
        "ambiguous %d\n",
        cal[c].name.c_str(), q.frames_labelled, q.frames_used, q.label_status[1], q.label_status[2],
        q.label_status[3], q.label_status[4]);
  }
  std::printf("  worst camera pose error %.4f mm, %.5f deg\n", worst_mm, worst_deg);
  std::printf(
      "  3D RMS error over %d marker views: true rig %.4f mm, calibrated rig %.4f mm "
      "(ratio %.3f)\n",
      n, rms_true, rms_cal, rms_cal / rms_true);
  std::printf("  aligned 3D RMS error of the calibrated rig %.4f mm (ratio to the true rig %.3f)\n",
              rms_aligned, rms_aligned / rms_true);
  std::printf("  wand length RMS error with the true rig over %d frames: %.4f mm\n", wl_n,
              std::sqrt(wl_ss / std::max(1, wl_n)));
  std::printf(
      "  ground frame: fit RMS %.4f mm; camera centre error max %.4f mm, rotation error "
      "max %.5f deg\n",
      with_ground.ground.rms_mm, ground_pos, ground_rot);
  std::printf("  time: simulate %.2f s, detect %.2f s, calibrate %.2f s\n", sec(t0, t1),
              sec(t1, t2), sec(t2, t3));
  std::filesystem::remove_all(dir);
  return 0;
}
