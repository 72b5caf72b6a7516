// Design: see rig_calibrator.h.
#include "rigcal/rig_calibrator.h"

#include <algorithm>
#include <cmath>

#include "detect/blob_detector.h"
#include "detect/edge_centre.h"
#include "formats/recording.h"
#include "rigcal/pairwise_init.h"
#include "rigcal/rig_quality.h"
#include "rigcal/wand_centres.h"
#include "stereo/two_view.h"

namespace mocap::rigcal {
namespace {

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

Expected<void> check_camera_count(std::size_t cameras, const std::string& recording) {
  if (cameras >= kMinRigCameras && cameras <= kMaxRigCameras) return {};
  return make_error(recording + "/rig.yaml", "cameras",
                    std::to_string(cameras) + " cameras listed, a rig calibration takes " +
                        std::to_string(kMinRigCameras) + " to " + std::to_string(kMaxRigCameras));
}

double expected_radial_stretch(const CameraModel& cam, const Vec2& px) noexcept {
  Vec2 xn;
  if (!undistort_pixel(cam, px, xn)) return 1.0;
  const double r2 = xn.squaredNorm();
  const double r4 = r2 * r2;
  const auto& k = cam.distortion;
  const double s_t = 1.0 + k[0] * r2 + k[1] * r4 + k[4] * r4 * r2;
  const double s_r = 1.0 + 3.0 * k[0] * r2 + 5.0 * k[1] * r4 + 7.0 * k[4] * r4 * r2;
  const double radial = std::fabs(s_r * std::sqrt(1.0 + r2));  // 1 / cos(off-axis angle)
  const double tangential = std::fabs(s_t);
  return radial > 0.0 && tangential > 0.0 ? radial / tangential : 1.0;
}

double expected_roundness(const CameraModel& cam, const Vec2& px) noexcept {
  const double s = expected_radial_stretch(cam, px);
  return s > 1.0 ? 1.0 / s : s;
}

Expected<DetectedRecording> detect_recording(const std::string& dir, const RigCalOptions& opt,
                                             const std::vector<CameraModel>* cams,
                                             const WandSpec* wand) {
  auto rec = Recording::open(dir);
  if (!rec) return rec.error();
  const std::size_t C = rec->rig().cameras.size();
  if (auto v = check_camera_count(C, dir); !v) return v.error();
  if (cams && cams->size() != C)
    return make_error(dir + "/rig.yaml", "cameras",
                      std::to_string(C) + " cameras, but intrinsics for " +
                          std::to_string(cams->size()) + " given");
  std::vector<Image> img(C);
  std::vector<detect::BlobDetector> det;
  for (std::size_t c = 0; c < C; ++c) {
    auto d = detect::BlobDetector::create(opt.detector, rec->rig().cameras[c].width,
                                          rec->rig().cameras[c].height);
    if (!d) return d.error();
    det.push_back(std::move(*d));
  }
  // A blob recording (formats/recording.h): its blob lists, as the recorder's detector
  // found them; the edge fits need the images, so the centres are the centroids and
  // partly hidden balls are left out (docs/rig_calibration.md, "Blob recordings").
  const bool from_blobs = rec->has_blobs();
  const bool edges = opt.edge_centres && !from_blobs;
  detect::BlobList list = det[0].make_blob_list();
  if (from_blobs && list.capacity() < rec->max_blobs()) list.set_capacity(rec->max_blobs());
  std::vector<std::uint8_t> scratch;
  DetectedRecording out;
  out.notes = rec->warnings();
  if (from_blobs && opt.edge_centres)
    out.notes.push_back(dir +
                        ": a blob recording: the balls' centres are the recorded blob "
                        "centroids (no edge fits without images; partly hidden balls "
                        "left out)");
  out.blobs.assign(rec->frames().size(), std::vector<std::vector<Vec2>>(C));
  out.info.assign(rec->frames().size(), std::vector<std::vector<CentreInfo>>(C));
  std::vector<const detect::Blob*> kept;
  std::vector<bool> round;  // per kept blob: as round as a whole ball there
  std::vector<int> role;    // per kept blob: -1 not on the wand, else its WandBallRole
  std::vector<Vec2> scaled;
  std::vector<std::size_t> index;
  std::vector<int> order;
  const detect::EdgeCentreConfig edge_cfg{};
  WandCentres wand_centres(edge_cfg);
  detect::EdgeSamples samples;
  for (std::size_t f = 0; f < rec->frames().size(); ++f) {
    for (std::size_t c = 0; c < C; ++c) {
      if (from_blobs) {
        auto r = rec->load_blobs(static_cast<int>(c), rec->frames()[f].frame, list, scratch);
        if (!r) return r.error();
        if (*r == FrameLoad::kMissing) continue;
      } else {
        auto r = rec->load_frame(static_cast<int>(c), rec->frames()[f].frame, img[c]);
        if (!r) return r.error();
        if (*r == FrameLoad::kMissing) continue;
        det[c].detect(img[c].view(), list);
      }
      const CameraModel& cam = cams ? (*cams)[c] : rec->rig().cameras[c];
      kept.clear();
      round.clear();
      for (const detect::Blob& b : list) {
        if (b.has(detect::kBlobTouchesBorder) || b.has(detect::kBlobMerged) ||
            b.has(detect::kBlobSplit))
          continue;
        const Vec2 px(b.x_px, b.y_px);
        const bool is_round =
            !(opt.min_roundness > 0.0 &&
              static_cast<double>(b.roundness) < opt.min_roundness * expected_roundness(cam, px));
        // A blob less round than a whole ball is kept only as a wand ball whose edge is
        // fitted (below): its centroid is biased, the fit leaves the hidden rim out.
        if (!is_round && !(edges && wand)) continue;
        kept.push_back(&b);
        round.push_back(is_round);
      }
      // The wand in this image, labelled on the centroids: its balls' centres come from
      // WandCentres (the rim along the wand's axis left out on the rod's side).
      Vec2 axis = Vec2::Zero();
      role.assign(kept.size(), -1);
      if (edges && wand) {
        // Labelled on every kept blob, else (a less round stray or a piece of a ball
        // cut in two on the wand's segment) on the round ones alone.
        auto label = [&](bool round_only) {
          scaled.clear();
          index.clear();
          for (std::size_t i = 0; i < kept.size(); ++i) {
            Vec2 xn;
            if (round_only && !round[i]) continue;
            if (!undistort_pixel(cam, Vec2(kept[i]->x_px, kept[i]->y_px), xn)) continue;
            scaled.push_back(to_scaled(cam, xn));
            index.push_back(i);
          }
          return label_wand(*wand, opt.label, scaled, order) == LabelStatus::kOk;
        };
        if (label(false) || label(true)) {
          const detect::Blob& a = *kept[index[static_cast<std::size_t>(order.front())]];
          const detect::Blob& z = *kept[index[static_cast<std::size_t>(order.back())]];
          axis = Vec2(z.x_px - a.x_px, z.y_px - a.y_px);
          for (std::size_t k = 0; k < order.size(); ++k) {
            const WandBallRole w = k == 0                  ? WandBallRole::kFirst
                                   : k + 1 == order.size() ? WandBallRole::kLast
                                                           : WandBallRole::kMiddle;
            role[index[static_cast<std::size_t>(order[k])]] = static_cast<int>(w);
          }
        }
      }
      auto& centres = out.blobs[f][c];
      auto& info = out.info[f][c];
      for (std::size_t i = 0; i < kept.size(); ++i) {
        const detect::Blob& b = *kept[i];
        if (!round[i] && role[i] < 0) continue;  // not a wand ball: a stray or a cut piece
        centres.emplace_back(b.x_px, b.y_px);
        info.push_back(CentreInfo{Eigen::Matrix2d::Zero(), !round[i]});
        if (!edges) continue;
        const Vec2 radial = centres.back() - Vec2(cam.cx, cam.cy);
        const bool sampled =
            detect::sample_edge(img[c].view(), b, list.levels().noise_dn, radial.x(), radial.y(),
                                expected_radial_stretch(cam, centres.back()), edge_cfg, samples);
        if (role[i] >= 0) {  // WandCentres::apply() writes it (else: the centroid, if round)
          if (!(sampled && wand_centres.add(samples, cam, static_cast<WandBallRole>(role[i]), axis,
                                            f, c, centres.size() - 1, !round[i])) &&
              !round[i]) {
            centres.pop_back();
            info.pop_back();
          }
          continue;
        }
        if (!sampled) continue;  // the centroid
        const detect::EdgeCentre e = detect::fit_edge_centre(samples, edge_cfg);
        if (!e.ok) continue;
        Vec2 ball;
        if (!ball_centre_pixel(cam, Vec2(e.x_px, e.y_px), e.radius_px, ball)) continue;
        centres.back() = ball;
        info.back().cov_px2 = e.cov_px2;
      }
    }
  }
  if (edges && wand) {
    out.rod_cut = wand_centres.choose(opt.rod_cut_deg, false);
    out.rod_cut_partly_hidden = wand_centres.choose(opt.rod_cut_deg, true);
    wand_centres.apply(out.rod_cut, out.blobs, &out.info, &out.rod_cut_partly_hidden);
  }
  return out;
}

Expected<RigCalResult> calibrate_from_blobs(const FrameBlobs& blobs, const WandSpec& wand,
                                            const std::vector<CameraModel>& intrinsics,
                                            const RigCalOptions& opt, const std::string& source,
                                            const FrameCentreInfo* info) {
  if (auto v = validate_wand(wand, "wand"); !v) return v.error();
  const std::size_t C = intrinsics.size();
  if (auto v = check_camera_count(C, source); !v) return v.error();
  for (std::size_t f = 0; f < blobs.size(); ++f) {
    if (blobs[f].size() != C)
      return make_error(source, "frame " + std::to_string(f),
                        "blobs of " + std::to_string(blobs[f].size()) + " cameras, the rig has " +
                            std::to_string(C));
  }
  if (info && info->size() != blobs.size())
    return make_error(
        source, "centre info",
        std::to_string(info->size()) + " frames, the blobs have " + std::to_string(blobs.size()));
  RigCalResult res;
  res.cameras = intrinsics;
  res.quality.resize(C);
  res.frames_total = static_cast<int>(blobs.size());
  // 1. Label the wand in every image; keep the frames labelled in >= 2 cameras.
  std::vector<WandFrame> frames;
  std::vector<int> order;
  std::vector<Vec2> scaled, px;
  std::vector<std::size_t> slot;
  for (std::size_t f = 0; f < blobs.size(); ++f) {
    WandFrame wf;
    wf.frame = static_cast<int>(f);
    wf.px.resize(C);
    // What is known of the centres, where given for every blob of the image.
    if (info) wf.info.resize(C);
    for (std::size_t c = 0; c < C; ++c) {
      const CameraModel& cam = res.cameras[c];
      const bool with_info =
          info && (*info)[f].size() == C && (*info)[f][c].size() == blobs[f][c].size();
      scaled.clear();
      px.clear();
      slot.clear();
      for (std::size_t i = 0; i < blobs[f][c].size(); ++i) {
        Vec2 xn;
        if (!undistort_pixel(cam, blobs[f][c][i], xn)) continue;
        scaled.push_back(to_scaled(cam, xn));
        px.push_back(blobs[f][c][i]);
        slot.push_back(i);
      }
      const LabelStatus s = label_wand(wand, opt.label, scaled, order);
      ++res.quality[c].label_status[static_cast<std::size_t>(s)];
      if (s != LabelStatus::kOk) continue;
      ++res.quality[c].frames_labelled;
      for (int i : order) {
        wf.px[c].push_back(px[static_cast<std::size_t>(i)]);
        if (with_info) wf.info[c].push_back((*info)[f][c][slot[static_cast<std::size_t>(i)]]);
        res.quality[c].wand_points_px.push_back(px[static_cast<std::size_t>(i)]);
      }
    }
    if (wf.cameras_labelled() >= 2) frames.push_back(std::move(wf));
  }
  for (std::size_t c = 0; c < C; ++c) {
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
                      std::string("too few frames: the wand was found in ") +
                          (C == 2 ? "both cameras" : "at least two cameras") + " in only " +
                          std::to_string(res.frames_both) + " of " + std::to_string(blobs.size()) +
                          " frames (need at least " + std::to_string(opt.min_frames) + ")");
  }
  // 2.-3. Initial rig, pairwise from camera 0, metric from the wand length.
  PairwiseInitOptions po;
  po.min_shared_frames = opt.min_frames;
  po.max_spacing_error = opt.max_spacing_error;
  po.seed = opt.seed;
  auto init = initialise_rig(wand, frames, res.cameras, po, source);
  if (!init) return init.error();
  for (std::size_t c = 1; c < C; ++c) {
    res.essential_inliers += init->essential_inliers[c];
    res.quality[c].essential_inliers = init->essential_inliers[c];
    res.quality[c].initialised_from =
        res.cameras[static_cast<std::size_t>(init->reference[c])].name;
  }
  std::vector<WandPose> poses = std::move(init->poses);
  std::vector<bool> use = std::move(init->use);
  // 4. Bundle adjustment: extrinsics first, then (maybe) intrinsics. The second pass
  // starts again from every frame: wrong intrinsics make good frames look like outliers.
  const std::vector<bool> use_initial = use;
  BundleOptions bo;
  bo.weight_by_covariance = opt.weight_centres;
  auto st = bundle_adjust(wand, frames, use, res.cameras, poses, bo);
  if (!st) return Error{source + ": " + st.error().message};
  bo.refine_camera = refine_decision(res, *st, opt);
  if (std::find(bo.refine_camera.begin(), bo.refine_camera.end(), true) != bo.refine_camera.end()) {
    use = use_initial;
    st = bundle_adjust(wand, frames, use, res.cameras, poses, bo);
    if (!st) return Error{source + ": " + st.error().message};
  }
  res.bundle = *st;
  res.frames_used = st->frames_used;
  // 5. Quality.
  if (auto q = fill_quality(res, wand, frames, use, opt, source); !q) return q.error();
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
