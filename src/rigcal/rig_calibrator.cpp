// Design: see rig_calibrator.h.
#include "rigcal/rig_calibrator.h"

#include <algorithm>
#include <cmath>
#include <cstdarg>
#include <cstdio>

#include "core/median.h"
#include "detect/blob_detector.h"
#include "formats/recording.h"
#include "rigcal/essential.h"
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

double median(std::vector<double> v) { return v.empty() ? 0.0 : median_in_place(v); }

double coverage_of(const std::vector<Vec2>& pts, const CameraModel& cam, int cols, int rows) {
  std::vector<bool> cell(static_cast<std::size_t>(cols * rows), false);
  for (const Vec2& p : pts) {
    const int cx = std::clamp(static_cast<int>(p.x() * cols / cam.width), 0, cols - 1);
    const int cy = std::clamp(static_cast<int>(p.y() * rows / cam.height), 0, rows - 1);
    cell[static_cast<std::size_t>(cy * cols + cx)] = true;
  }
  return static_cast<double>(std::count(cell.begin(), cell.end(), true)) /
         static_cast<double>(cell.size());
}

}  // namespace

double expected_roundness(const CameraModel& cam, const Vec2& px) noexcept {
  Vec2 xn;
  if (!undistort_pixel(cam, px, xn)) return 1.0;
  const double r2 = xn.squaredNorm();
  const double r4 = r2 * r2;
  const auto& k = cam.distortion;
  const double s_t = 1.0 + k[0] * r2 + k[1] * r4 + k[4] * r4 * r2;
  const double s_r = 1.0 + 3.0 * k[0] * r2 + 5.0 * k[1] * r4 + 7.0 * k[4] * r4 * r2;
  const double radial = s_r * std::sqrt(1.0 + r2);  // 1 / cos(off-axis angle)
  const double a = std::fabs(radial), b = std::fabs(s_t);
  return std::max(a, b) > 0.0 ? std::min(a, b) / std::max(a, b) : 1.0;
}

Expected<FrameBlobs> detect_recording(const std::string& dir, const detect::DetectorConfig& cfg,
                                      double min_roundness,
                                      const std::array<CameraModel, 2>* cams) {
  auto rec = Recording::open(dir);
  if (!rec) return rec.error();
  if (rec->rig().cameras.size() < 2)
    return make_error(dir + "/rig.yaml", "cameras", "a stereo recording needs two cameras");
  std::array<Image, 2> img;
  std::vector<detect::BlobDetector> det;
  for (std::size_t c = 0; c < 2; ++c) {
    auto d = detect::BlobDetector::create(cfg, rec->rig().cameras[c].width,
                                          rec->rig().cameras[c].height);
    if (!d) return d.error();
    det.push_back(std::move(*d));
  }
  detect::BlobList list = det[0].make_blob_list();
  FrameBlobs out(rec->frames().size());
  for (std::size_t f = 0; f < rec->frames().size(); ++f) {
    for (std::size_t c = 0; c < 2; ++c) {
      auto r = rec->load_frame(static_cast<int>(c), rec->frames()[f].frame, img[c]);
      if (!r) return r.error();
      if (*r == FrameLoad::kMissing) continue;
      det[c].detect(img[c].view(), list);
      for (const detect::Blob& b : list) {
        if (b.has(detect::kBlobTouchesBorder) || b.has(detect::kBlobMerged) ||
            b.has(detect::kBlobSplit))
          continue;
        const Vec2 px(b.x_px, b.y_px);
        if (min_roundness > 0.0 &&
            static_cast<double>(b.roundness) <
                min_roundness * expected_roundness(cams ? (*cams)[c] : rec->rig().cameras[c], px))
          continue;
        out[f][c].push_back(px);
      }
    }
  }
  return out;
}

Expected<RigCalResult> calibrate_from_blobs(const FrameBlobs& blobs, const WandSpec& wand,
                                            const std::array<CameraModel, 2>& intrinsics,
                                            const RigCalOptions& opt, const std::string& source) {
  if (auto v = validate_wand(wand, "wand"); !v) return v.error();
  RigCalResult res;
  res.cameras = intrinsics;
  for (CameraModel& c : res.cameras) {
    c.R_cam_world = Mat3::Identity();
    c.t_cam_world = Vec3::Zero();
  }
  const std::size_t N = wand.markers_mm.size();
  res.frames_total = static_cast<int>(blobs.size());
  // 1. Label the wand in every image.
  std::vector<WandFrame> frames;
  std::vector<int> order;
  std::vector<Vec2> scaled;
  for (std::size_t f = 0; f < blobs.size(); ++f) {
    std::array<bool, 2> ok{};
    WandFrame wf;
    wf.frame = static_cast<int>(f);
    for (std::size_t c = 0; c < 2; ++c) {
      const CameraModel& cam = res.cameras[c];
      scaled.clear();
      std::vector<Vec2> px;
      for (const Vec2& p : blobs[f][c]) {
        Vec2 xn;
        if (!undistort_pixel(cam, p, xn)) continue;
        scaled.push_back(to_scaled(cam, xn));
        px.push_back(p);
      }
      const LabelStatus s = label_wand(wand, opt.label, scaled, order);
      ++res.quality[c].label_status[static_cast<std::size_t>(s)];
      if (s != LabelStatus::kOk) continue;
      ok[c] = true;
      ++res.quality[c].frames_labelled;
      for (int i : order) {
        wf.px[c].push_back(px[static_cast<std::size_t>(i)]);
        res.quality[c].wand_points_px.push_back(px[static_cast<std::size_t>(i)]);
      }
    }
    if (ok[0] && ok[1]) frames.push_back(std::move(wf));
  }
  for (std::size_t c = 0; c < 2; ++c) {
    res.quality[c].name = res.cameras[c].name;
    res.quality[c].coverage = coverage_of(res.quality[c].wand_points_px, res.cameras[c],
                                          opt.coverage_cols, opt.coverage_rows);
    if (res.quality[c].frames_labelled == 0) {
      return make_error(source, res.cameras[c].name,
                        "the wand was never found (0 of " + std::to_string(blobs.size()) +
                            " frames): is it in view, and do the spacings in the wand file "
                            "match the wand?");
    }
  }
  res.frames_both = static_cast<int>(frames.size());
  if (res.frames_both < opt.min_frames) {
    return make_error(source, "frames",
                      "too few frames: the wand was found in both cameras in only " +
                          std::to_string(res.frames_both) + " of " + std::to_string(blobs.size()) +
                          " frames (need at least " + std::to_string(opt.min_frames) + ")");
  }
  // 2. Essential matrix.
  std::vector<Vec2> x0, x1;
  for (const WandFrame& wf : frames) {
    for (std::size_t k = 0; k < N; ++k) {
      Vec2 a, b;
      undistort_pixel(res.cameras[0], wf.px[0][k], a);
      undistort_pixel(res.cameras[1], wf.px[1][k], b);
      x0.push_back(a);
      x1.push_back(b);
    }
  }
  EssentialOptions eo;
  eo.seed = opt.seed;
  eo.threshold = 2.0 / (0.5 * (res.cameras[0].fx + res.cameras[1].fx));
  auto rel = estimate_relative_pose(x0, x1, eo);
  if (!rel) return Error{source + ": " + rel.error().message};
  res.essential_inliers = rel->inlier_count;
  if (rel->inlier_count * 2 < static_cast<int>(x0.size()))
    return make_error(source, "essential",
                      "only " + std::to_string(rel->inlier_count) + " of " +
                          std::to_string(x0.size()) +
                          " wand points agree with one epipolar geometry (wrong intrinsics?)");
  // 3. Scale from the wand length; check the inner markers' spacing.
  std::vector<double> lengths;
  std::vector<std::vector<double>> fractions(N);
  std::vector<WandPose> poses(frames.size());
  // Frames with an epipolar outlier or a point behind a camera do not take part.
  std::vector<bool> use(frames.size(), true);
  for (std::size_t f = 0; f < frames.size(); ++f) {
    std::vector<Vec3> X(N);
    for (std::size_t k = 0; k < N; ++k) {
      X[k] = triangulate_linear(rel->R_1_0, rel->t_1_0, x0[f * N + k], x1[f * N + k]);
      const bool front = X[k].z() > 0.0 && (rel->R_1_0 * X[k] + rel->t_1_0).z() > 0.0;
      if (!rel->inlier[f * N + k] || !front) use[f] = false;
    }
    if (!use[f]) continue;
    const double L = (X[N - 1] - X[0]).norm();
    lengths.push_back(L);
    poses[f].A = X[0];
    poses[f].d = (X[N - 1] - X[0]) / std::max(L, 1e-12);
    for (std::size_t k = 1; k + 1 < N; ++k) {
      fractions[k].push_back((X[k] - X[0]).dot(poses[f].d) / std::max(L, 1e-12));
    }
  }
  const double unit_len = median(lengths);
  if (!(unit_len > 0.0)) return make_error(source, "scale", "degenerate wand triangulation");
  const double scale = wand.length_mm() / unit_len;
  for (std::size_t k = 1; k + 1 < N; ++k) {
    const double measured = median(fractions[k]);
    const double expected = (wand.markers_mm[k] - wand.markers_mm[0]) / wand.length_mm();
    if (std::fabs(measured - expected) > opt.max_spacing_error) {
      return make_error(source, "wand",
                        fmt("wrong wand spacing: marker %zu measured at %.1f mm from marker 0, "
                            "the wand file says %.1f mm",
                            k, measured * wand.length_mm(), expected * wand.length_mm()));
    }
  }
  res.cameras[1].R_cam_world = rel->R_1_0;
  res.cameras[1].t_cam_world = rel->t_1_0 * scale;
  for (WandPose& p : poses) p.A *= scale;
  // 4. Bundle adjustment: extrinsics first, then (maybe) intrinsics. The second pass
  // starts again from every frame: wrong intrinsics make good frames look like outliers.
  const std::vector<bool> use_initial = use;
  BundleOptions bo;
  auto st = bundle_adjust(wand, frames, use, res.cameras, poses, bo);
  if (!st) return Error{source + ": " + st.error().message};
  const bool coverage_ok = res.quality[0].coverage >= opt.refine_coverage &&
                           res.quality[1].coverage >= opt.refine_coverage;
  const bool enough = st->frames_used >= opt.refine_min_frames;
  res.intrinsics_refined = opt.intrinsics == IntrinsicsMode::kRefine ||
                           (opt.intrinsics == IntrinsicsMode::kAuto && coverage_ok && enough);
  if (res.intrinsics_refined) {
    bo.refine_intrinsics = true;
    use = use_initial;
    st = bundle_adjust(wand, frames, use, res.cameras, poses, bo);
    if (!st) return Error{source + ": " + st.error().message};
    res.intrinsics_note = "intrinsics refined (fx, fy, cx, cy, k1, k2; p1, p2, k3 kept)";
  } else if (opt.intrinsics == IntrinsicsMode::kFixed) {
    res.intrinsics_note = "intrinsics kept as given (--intrinsics-mode fixed)";
  } else {
    res.intrinsics_note = fmt("intrinsics kept as given: coverage %.2f / %.2f",
                              res.quality[0].coverage, res.quality[1].coverage) +
                          fmt(" (refined above %.2f) with %d frames (refined from %d)",
                              opt.refine_coverage, st->frames_used, opt.refine_min_frames);
  }
  res.bundle = *st;
  res.frames_used = st->frames_used;
  for (std::size_t c = 0; c < 2; ++c) res.quality[c].reprojection_rms_px = st->rms_px[c];
  res.baseline_mm = res.cameras[1].center_world().norm();
  // 5. Wand length from independently triangulated ends.
  auto g = make_stereo_geometry(res.cameras[0], res.cameras[1]);
  if (!g) return make_error(source, "rig", g.error().message);
  double sum = 0.0, sum2 = 0.0;
  for (std::size_t f = 0; f < frames.size(); ++f) {
    if (!use[f]) continue;
    Vec3 a, b;
    double r0 = 0.0, r1 = 0.0;
    if (!triangulate_pixels(*g, res.cameras[0], res.cameras[1], frames[f].px[0][0],
                            frames[f].px[1][0], a, r0) ||
        !triangulate_pixels(*g, res.cameras[0], res.cameras[1], frames[f].px[0][N - 1],
                            frames[f].px[1][N - 1], b, r1))
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
  return res;
}

Expected<void> set_ground_frame(RigCalResult& res, const FrameBlobs& lframe_blobs,
                                const LFrameSpec& lframe, const RigCalOptions& opt,
                                const std::string& source) {
  if (auto v = validate_lframe(lframe, "lframe"); !v) return v.error();
  auto gf = estimate_ground_frame(lframe, lframe_blobs, res.cameras, opt.ground, source);
  if (!gf) return gf.error();
  res.ground = *gf;
  res.has_ground = true;
  apply_ground_frame(res.cameras, gf->T_cam0_lframe);
  return {};
}

}  // namespace mocap::rigcal
