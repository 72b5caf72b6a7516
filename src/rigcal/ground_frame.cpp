// Design: see ground_frame.h.
#include "rigcal/ground_frame.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cstdio>
#include <functional>

#include "stereo/two_view.h"

namespace mocap::rigcal {

void apply_ground_frame(std::vector<CameraModel>& cams, const Iso3& T_cam0_lframe) {
  for (CameraModel& c : cams) {
    const Iso3 T = c.T_cam_world() * T_cam0_lframe;
    c.R_cam_world = T.linear();
    c.t_cam_world = T.translation();
  }
}

Expected<GroundFrameResult> estimate_ground_frame(const LFrameSpec& lframe, const FrameBlobs& blobs,
                                                  const std::vector<CameraModel>& cams,
                                                  const GroundFrameOptions& opt,
                                                  const std::string& source) {
  const std::size_t C = cams.size();
  std::vector<StereoGeometry> pair_geometry;  // pairs (a < b) in lexicographic order
  for (std::size_t a = 0; a < C; ++a) {
    for (std::size_t b = a + 1; b < C; ++b) {
      auto g = make_stereo_geometry(cams[a], cams[b]);
      if (!g) return g.error();
      pair_geometry.push_back(*g);
    }
  }
  struct Cluster {
    Vec3 sum = Vec3::Zero();
    int count = 0;   // points
    int frames = 0;  // frames that added a point
    int last_frame = -1;
    Vec3 mean() const { return sum / count; }
  };
  std::vector<Cluster> clusters;
  int frames = 0;
  std::vector<std::vector<Vec2>> s(C), n(C);  // per camera: pixel-scaled, normalised
  for (std::size_t f = 0; f < blobs.size(); ++f) {
    const auto& fb = blobs[f];
    if (fb.size() != C)
      return make_error(
          source, "frame " + std::to_string(f),
          "blobs of " + std::to_string(fb.size()) + " cameras, the rig has " + std::to_string(C));
    int seen = 0;
    for (std::size_t c = 0; c < C; ++c) {
      s[c].clear();
      n[c].clear();
      for (const Vec2& p : fb[c]) {
        Vec2 xn;
        if (undistort_pixel(cams[c], p, xn)) {
          n[c].push_back(xn);
          s[c].push_back(to_scaled(cams[c], xn));
        }
      }
      seen += n[c].empty() ? 0 : 1;
    }
    if (seen < 2) continue;
    ++frames;
    std::size_t pair = 0;
    for (std::size_t a = 0; a < C; ++a) {
      for (std::size_t b = a + 1; b < C; ++b, ++pair) {
        const StereoGeometry& g = pair_geometry[pair];
        for (std::size_t i = 0; i < n[a].size(); ++i) {
          for (std::size_t j = 0; j < n[b].size(); ++j) {
            double d0 = 0.0, d1 = 0.0;
            epipolar_distances_px(g, s[a][i], s[b][j], d0, d1);
            if (std::max(d0, d1) > opt.max_epipolar_px) continue;
            Vec3 X;
            if (!triangulate_niter2(g, n[a][i], n[b][j], X)) continue;
            Cluster* hit = nullptr;
            for (Cluster& c : clusters) {
              if ((c.mean() - X).norm() < opt.cluster_radius_mm) {
                hit = &c;
                break;
              }
            }
            if (!hit) {
              clusters.push_back(Cluster{});
              hit = &clusters.back();
            }
            hit->sum += X;
            ++hit->count;
            if (hit->last_frame != static_cast<int>(f)) {
              hit->last_frame = static_cast<int>(f);
              ++hit->frames;
            }
          }
        }
      }
    }
  }
  const std::size_t M = lframe.markers_mm.size();
  std::vector<Vec3> pts;
  std::sort(clusters.begin(), clusters.end(),
            [](const Cluster& a, const Cluster& b) { return a.count > b.count; });
  for (const Cluster& c : clusters) {
    if (c.frames * 2 >= frames && pts.size() < M + 4) pts.push_back(c.mean());
  }
  if (frames == 0 || pts.size() < M) {
    return make_error(source, "lframe",
                      "found " + std::to_string(pts.size()) + " steady markers in " +
                          std::to_string(frames) + " frames, the L-frame has " + std::to_string(M));
  }
  // Ordered choices of clusters for the markers, pruned by pairwise distances.
  const double tol = 4.0 * opt.max_rms_mm + 2.0;
  std::vector<int> pick(M, -1);
  std::vector<bool> taken(pts.size(), false);
  double best_rms = 1e300;
  std::vector<int> best;
  Eigen::Matrix<double, 3, Eigen::Dynamic> src(3, static_cast<Eigen::Index>(M)),
      dst(3, static_cast<Eigen::Index>(M));
  std::function<void(std::size_t)> rec = [&](std::size_t k) {
    if (k == M) {
      for (std::size_t i = 0; i < M; ++i) {
        src.col(static_cast<Eigen::Index>(i)) = lframe.markers_mm[i];
        dst.col(static_cast<Eigen::Index>(i)) = pts[static_cast<std::size_t>(pick[i])];
      }
      const Eigen::Matrix4d T = Eigen::umeyama(src, dst, false);
      double ss = 0.0;
      for (std::size_t i = 0; i < M; ++i) {
        const Vec3 p = T.topLeftCorner<3, 3>() * lframe.markers_mm[i] + T.topRightCorner<3, 1>();
        ss += (p - pts[static_cast<std::size_t>(pick[i])]).squaredNorm();
      }
      const double rms = std::sqrt(ss / static_cast<double>(M));
      if (rms < best_rms) {
        best_rms = rms;
        best = pick;
      }
      return;
    }
    for (std::size_t c = 0; c < pts.size(); ++c) {
      if (taken[c]) continue;
      bool ok = true;
      for (std::size_t i = 0; i < k && ok; ++i) {
        const double dm = (lframe.markers_mm[i] - lframe.markers_mm[k]).norm();
        const double dp = (pts[static_cast<std::size_t>(pick[i])] - pts[c]).norm();
        ok = std::fabs(dm - dp) < tol;
      }
      if (!ok) continue;
      taken[c] = true;
      pick[k] = static_cast<int>(c);
      rec(k + 1);
      taken[c] = false;
    }
  };
  rec(0);
  if (best.empty() || best_rms > opt.max_rms_mm) {
    char buf[200];
    std::snprintf(buf, sizeof buf,
                  "the steady markers do not match the L-frame's layout (best rigid fit %s mm "
                  "RMS, limit %.1f mm): check lframe.markers_mm",
                  best.empty() ? "none" : std::to_string(best_rms).c_str(), opt.max_rms_mm);
    return make_error(source, "lframe", buf);
  }
  GroundFrameResult out;
  for (std::size_t i = 0; i < M; ++i) {
    src.col(static_cast<Eigen::Index>(i)) = lframe.markers_mm[i];
    dst.col(static_cast<Eigen::Index>(i)) = pts[static_cast<std::size_t>(best[i])];
    out.markers_cam0.push_back(pts[static_cast<std::size_t>(best[i])]);
  }
  const Eigen::Matrix4d T = Eigen::umeyama(src, dst, false);
  out.T_cam0_lframe = make_iso(T.topLeftCorner<3, 3>(), T.topRightCorner<3, 1>());
  out.rms_mm = best_rms;
  out.frames = frames;
  return out;
}

}  // namespace mocap::rigcal
