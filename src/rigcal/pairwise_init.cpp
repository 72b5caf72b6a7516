// Design: see pairwise_init.h.
#include "rigcal/pairwise_init.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "core/median.h"
#include "rigcal/essential.h"
#include "stereo/nview.h"

namespace mocap::rigcal {
namespace {

double median(std::vector<double> v) { return v.empty() ? 0.0 : median_in_place(v); }

bool labelled(const WandFrame& wf, std::size_t c) { return !wf.px[c].empty(); }

// Initialises camera c from the already initialised reference r: cams[c]'s extrinsics,
// and the wand poses of the pair's frames that have none yet.
Expected<int> init_pair(const WandSpec& wand, const std::vector<WandFrame>& frames,
                        std::vector<CameraModel>& cams, std::size_t r, std::size_t c,
                        const PairwiseInitOptions& opt, const std::string& source,
                        std::vector<bool>& has_pose, std::vector<bool>& bad,
                        std::vector<WandPose>& poses) {
  const std::size_t N = wand.markers_mm.size();
  const std::string pair = cams[r].name + "-" + cams[c].name;
  std::vector<std::size_t> idx;
  std::vector<Vec2> xr, xc;
  for (std::size_t f = 0; f < frames.size(); ++f) {
    if (!labelled(frames[f], r) || !labelled(frames[f], c)) continue;
    idx.push_back(f);
    for (std::size_t k = 0; k < N; ++k) {
      Vec2 a, b;
      undistort_pixel(cams[r], frames[f].px[r][k], a);
      undistort_pixel(cams[c], frames[f].px[c][k], b);
      xr.push_back(a);
      xc.push_back(b);
    }
  }
  EssentialOptions eo;
  eo.seed = opt.seed;
  eo.threshold = 2.0 / (0.5 * (cams[r].fx + cams[c].fx));
  auto rel = estimate_relative_pose(xr, xc, eo);
  if (!rel) return Error{source + ": " + pair + ": " + rel.error().message};
  if (rel->inlier_count * 2 < static_cast<int>(xr.size()))
    return make_error(source, "essential",
                      "only " + std::to_string(rel->inlier_count) + " of " +
                          std::to_string(xr.size()) + " wand points of " + pair +
                          " agree with one epipolar geometry (wrong intrinsics?)");
  // Scale from the wand length; check the inner markers' spacing.
  std::vector<double> lengths;
  std::vector<std::vector<double>> fractions(N);
  std::vector<WandPose> local(idx.size());  // reference camera's frame, unit scale
  std::vector<bool> ok(idx.size(), true);
  std::vector<Vec3> X(N);
  for (std::size_t i = 0; i < idx.size(); ++i) {
    for (std::size_t k = 0; k < N; ++k) {
      X[k] = triangulate_linear(rel->R_1_0, rel->t_1_0, xr[i * N + k], xc[i * N + k]);
      const bool front = X[k].z() > 0.0 && (rel->R_1_0 * X[k] + rel->t_1_0).z() > 0.0;
      if (!rel->inlier[i * N + k] || !front) ok[i] = false;
    }
    if (!ok[i]) {
      bad[idx[i]] = true;
      continue;
    }
    const double L = (X[N - 1] - X[0]).norm();
    lengths.push_back(L);
    local[i].A = X[0];
    local[i].d = (X[N - 1] - X[0]) / std::max(L, 1e-12);
    for (std::size_t k = 1; k + 1 < N; ++k)
      fractions[k].push_back((X[k] - X[0]).dot(local[i].d) / std::max(L, 1e-12));
  }
  const double unit_len = median(lengths);
  if (!(unit_len > 0.0))
    return make_error(source, "scale", "degenerate wand triangulation (" + pair + ")");
  const double scale = wand.length_mm() / unit_len;
  for (std::size_t k = 1; k + 1 < N; ++k) {
    const double measured = median(fractions[k]);
    const double expected = (wand.markers_mm[k] - wand.markers_mm[0]) / wand.length_mm();
    if (std::fabs(measured - expected) > opt.max_spacing_error) {
      char buf[200];
      std::snprintf(buf, sizeof buf,
                    "wrong wand spacing: marker %zu measured at %.1f mm from marker 0, the wand "
                    "file says %.1f mm",
                    k, measured * wand.length_mm(), expected * wand.length_mm());
      return make_error(source, "wand", buf);
    }
  }
  // T_c_cam0 = T_c_r * T_r_cam0; wand poses to camera 0's frame: X_0 = R_r0^T (X_r - t_r0).
  const Mat3 R_r0 = cams[r].R_cam_world;
  const Vec3 t_r0 = cams[r].t_cam_world;
  cams[c].R_cam_world = rel->R_1_0 * R_r0;
  cams[c].t_cam_world = rel->R_1_0 * t_r0 + rel->t_1_0 * scale;
  for (std::size_t i = 0; i < idx.size(); ++i) {
    const std::size_t f = idx[i];
    if (!ok[i] || has_pose[f]) continue;
    poses[f].A = R_r0.transpose() * (local[i].A * scale - t_r0);
    poses[f].d = R_r0.transpose() * local[i].d;
    has_pose[f] = true;
  }
  return rel->inlier_count;
}

// Wand pose of a frame from all its labelled cameras (at most kMaxCameras of them).
bool triangulate_frame(const WandSpec& wand, const WandFrame& wf,
                       const std::vector<CameraModel>& cams, WandPose& pose) {
  const CameraModel* cp[kMaxCameras];
  Vec3 X[2];
  const std::size_t ends[2] = {0, wand.markers_mm.size() - 1};
  for (int e = 0; e < 2; ++e) {
    Vec2 xn[kMaxCameras];
    int n = 0;
    for (std::size_t c = 0; c < cams.size() && n < kMaxCameras; ++c) {
      if (!labelled(wf, c)) continue;
      if (!undistort_pixel(cams[c], wf.px[c][ends[e]], xn[n])) continue;
      cp[n++] = &cams[c];
    }
    if (n < 2 || !triangulate_linear_nview(cp, xn, n, X[e])) return false;
  }
  const double L = (X[1] - X[0]).norm();
  if (!(L > 0.0)) return false;
  pose.A = X[0];
  pose.d = (X[1] - X[0]) / L;
  return true;
}

}  // namespace

int shared_frame_count(const std::vector<WandFrame>& frames, std::size_t a, std::size_t b) {
  int n = 0;
  for (const WandFrame& wf : frames) n += labelled(wf, a) && labelled(wf, b) ? 1 : 0;
  return n;
}

Expected<PairwiseInit> initialise_rig(const WandSpec& wand, const std::vector<WandFrame>& frames,
                                      std::vector<CameraModel>& cams,
                                      const PairwiseInitOptions& opt, const std::string& source) {
  const std::size_t C = cams.size();
  for (CameraModel& c : cams) {
    c.R_cam_world = Mat3::Identity();
    c.t_cam_world = Vec3::Zero();
  }
  std::vector<std::vector<int>> shared(C, std::vector<int>(C, 0));
  for (std::size_t a = 0; a < C; ++a)
    for (std::size_t b = a + 1; b < C; ++b)
      shared[a][b] = shared[b][a] = shared_frame_count(frames, a, b);
  PairwiseInit out;
  out.reference.assign(C, -1);
  out.shared_frames.assign(C, 0);
  out.essential_inliers.assign(C, 0);
  out.poses.assign(frames.size(), WandPose{});
  std::vector<bool> has_pose(frames.size(), false), bad(frames.size(), false);
  std::vector<bool> done(C, false);
  done[0] = true;
  for (std::size_t step = 1; step < C; ++step) {
    // Camera 0 first (in camera order), then the best-connected chain.
    std::size_t best_c = C, best_r = 0;
    int best_n = -1;
    for (std::size_t c = 1; c < C && best_c == C; ++c) {
      if (!done[c] && shared[0][c] >= opt.min_shared_frames) best_c = c;
    }
    if (best_c == C) {
      for (std::size_t c = 1; c < C; ++c) {
        if (done[c]) continue;
        for (std::size_t r = 0; r < C; ++r) {
          if (done[r] && shared[r][c] > best_n) {
            best_n = shared[r][c];
            best_c = c;
            best_r = r;
          }
        }
      }
      if (best_n < opt.min_shared_frames) {
        std::size_t c = 1;
        while (done[c]) ++c;
        int most = 0;
        for (std::size_t r = 0; r < C; ++r)
          if (done[r]) most = std::max(most, shared[r][c]);
        return make_error(source, cams[c].name,
                          "cannot be connected to " + cams[0].name +
                              ": the wand was labelled "
                              "together with an already calibrated camera in at most " +
                              std::to_string(most) + " frames (need at least " +
                              std::to_string(opt.min_shared_frames) + ")");
      }
    }
    auto inl = init_pair(wand, frames, cams, best_r, best_c, opt, source, has_pose, bad, out.poses);
    if (!inl) return inl.error();
    done[best_c] = true;
    out.reference[best_c] = static_cast<int>(best_r);
    out.shared_frames[best_c] = shared[best_r][best_c];
    out.essential_inliers[best_c] = *inl;
  }
  out.use.assign(frames.size(), false);
  for (std::size_t f = 0; f < frames.size(); ++f) {
    if (bad[f] || frames[f].cameras_labelled() < 2) continue;
    if (!has_pose[f]) has_pose[f] = triangulate_frame(wand, frames[f], cams, out.poses[f]);
    out.use[f] = has_pose[f];
  }
  return out;
}

}  // namespace mocap::rigcal
