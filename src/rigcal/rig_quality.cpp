// Design: see rig_quality.h.
#include "rigcal/rig_quality.h"

#include <cmath>
#include <cstdarg>
#include <cstdio>

#include "stereo/nview.h"
#include "stereo/two_view.h"

namespace mocap::rigcal {
namespace {

__attribute__((format(printf, 1, 2))) std::string fmt(const char* f, ...) {
  char buf[320];
  va_list ap;
  va_start(ap, f);
  std::vsnprintf(buf, sizeof buf, f, ap);
  va_end(ap);
  return buf;
}

// The names of the cameras with flag == want, comma separated.
std::string names_where(const RigCalResult& res, const std::vector<bool>& flag, bool want) {
  std::string s;
  for (std::size_t c = 0; c < flag.size(); ++c) {
    if (flag[c] != want) continue;
    s += (s.empty() ? "" : ", ") + res.cameras[c].name;
  }
  return s;
}

// One end of the wand (marker k) of a frame from its labelled cameras.
bool triangulate_marker(const std::vector<CameraModel>& cams,
                        const std::vector<StereoGeometry>& pair_geometry, const WandFrame& wf,
                        std::size_t k, Vec3& X) {
  const CameraModel* cp[kMaxCameras];
  Vec2 xn[kMaxCameras], px[kMaxCameras];
  std::size_t idx[kMaxCameras];
  int n = 0;
  for (std::size_t c = 0; c < cams.size() && n < kMaxCameras; ++c) {
    if (wf.px[c].empty()) continue;
    idx[n] = c;
    cp[n] = &cams[c];
    px[n] = wf.px[c][k];
    if (!undistort_pixel(cams[c], px[n], xn[n])) return false;
    ++n;
  }
  if (n == 2) {
    // The pair (a < b) in lexicographic order.
    const std::size_t C = cams.size(), a = idx[0], b = idx[1];
    const std::size_t pair = a * C - a * (a + 1) / 2 + (b - a - 1);
    double r = 0.0;
    return triangulate_pixels(pair_geometry[pair], cams[a], cams[b], px[0], px[1], X, r);
  }
  double rms = 0.0;
  return n > 2 && triangulate_linear_nview(cp, xn, n, X) && refine_gauss_newton(cp, px, n, X, rms);
}

}  // namespace

std::vector<bool> refine_decision(RigCalResult& res, const BundleStats& st,
                                  const RigCalOptions& opt) {
  const std::size_t C = res.cameras.size();
  std::vector<bool> refine(C, false);
  for (std::size_t c = 0; c < C; ++c) {
    const bool coverage_ok = res.quality[c].coverage >= opt.refine_coverage;
    const bool enough = st.frames_per_camera[c] >= opt.refine_min_frames;
    refine[c] = opt.intrinsics == IntrinsicsMode::kRefine ||
                (opt.intrinsics == IntrinsicsMode::kAuto && coverage_ok && enough);
    res.quality[c].intrinsics_refined = refine[c];
  }
  const std::string refined = names_where(res, refine, true);
  const std::string kept = names_where(res, refine, false);
  res.intrinsics_refined = !refined.empty();
  const char* what = "(fx, fy, cx, cy, k1, k2; p1, p2, k3 kept)";
  if (kept.empty()) {
    res.intrinsics_note = std::string("intrinsics refined ") + what;
  } else if (opt.intrinsics == IntrinsicsMode::kFixed) {
    res.intrinsics_note = "intrinsics kept as given (--intrinsics-mode fixed)";
  } else {
    std::string cov, frames;
    bool same_frames = true;
    for (std::size_t c = 0; c < C; ++c) {
      cov += (c ? " / " : "") + fmt("%.2f", res.quality[c].coverage);
      frames += (c ? " / " : "") + std::to_string(st.frames_per_camera[c]);
      same_frames = same_frames && st.frames_per_camera[c] == st.frames_per_camera[0];
    }
    if (same_frames) frames = std::to_string(st.frames_per_camera[0]);
    const std::string why = "coverage " + cov + fmt(" (refined above %.2f)", opt.refine_coverage) +
                            " with " + frames +
                            fmt(" frames (refined from %d)", opt.refine_min_frames);
    res.intrinsics_note = refined.empty() ? "intrinsics kept as given: " + why
                                          : "intrinsics refined for " + refined + " " + what +
                                                ", kept as given for " + kept + ": " + why;
  }
  return refine;
}

Expected<void> fill_quality(RigCalResult& res, const WandSpec& wand,
                            const std::vector<WandFrame>& frames, const std::vector<bool>& use,
                            const RigCalOptions& opt, const std::string& source) {
  const std::size_t C = res.cameras.size();
  const Iso3 T_cam0_world = res.cameras[0].T_cam_world();  // identity before a ground frame
  for (std::size_t c = 0; c < C; ++c) {
    CameraQuality& q = res.quality[c];
    q.reprojection_rms_px = res.bundle.rms_px[c];
    q.frames_used = res.bundle.frames_per_camera[c];
    q.T_cam_cam0 = res.cameras[c].T_cam_world() * T_cam0_world.inverse();
    q.baseline_mm = q.T_cam_cam0.inverse().translation().norm();
  }
  res.baseline_mm = res.quality[1].baseline_mm;
  // Wand length from independently triangulated ends.
  std::vector<StereoGeometry> pair_geometry;
  for (std::size_t a = 0; a < C; ++a) {
    for (std::size_t b = a + 1; b < C; ++b) {
      auto g = make_stereo_geometry(res.cameras[a], res.cameras[b]);
      if (!g) return make_error(source, "rig", g.error().message);
      pair_geometry.push_back(*g);
    }
  }
  const std::size_t N = wand.markers_mm.size();
  // A frame whose end balls are partly hidden in a camera (a cut rim: a noisier centre,
  // weighed less in the bundle) is left out: the figure is the length's scatter over
  // whole balls, comparable between recordings however much of the wand was hidden.
  auto end_balls_whole = [&](const WandFrame& wf) {
    for (const auto& cam : wf.info)
      if (cam.size() == N && (cam.front().partly_hidden || cam.back().partly_hidden)) return false;
    return true;
  };
  double sum = 0.0, sum2 = 0.0;
  for (std::size_t f = 0; f < frames.size(); ++f) {
    if (!use[f] || !end_balls_whole(frames[f])) continue;
    Vec3 a, b;
    if (!triangulate_marker(res.cameras, pair_geometry, frames[f], 0, a) ||
        !triangulate_marker(res.cameras, pair_geometry, frames[f], N - 1, b))
      continue;
    const double e = (b - a).norm() - wand.length_mm();
    sum += e;
    sum2 += e * e;
    ++res.wand_length_samples;
  }
  if (res.wand_length_samples > 0) {
    res.wand_length_mean_error_mm = sum / res.wand_length_samples;
    res.wand_length_rms_error_mm = std::sqrt(sum2 / res.wand_length_samples);
  }
  // Warnings.
  if (res.frames_used < opt.warn_frames)
    res.warnings.push_back(
        fmt("only %d wand frames used (%d or more recommended)", res.frames_used, opt.warn_frames));
  for (const CameraQuality& q : res.quality) {
    if (q.coverage < opt.warn_coverage)
      res.warnings.push_back(q.name + fmt(": the wand covered only %.0f%% of the image (%.0f%% or "
                                          "more recommended): wave it into the corners",
                                          100.0 * q.coverage, 100.0 * opt.warn_coverage));
  }
  return {};
}

}  // namespace mocap::rigcal
