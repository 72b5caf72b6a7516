// Design: see bundle.h.
#include "rigcal/bundle.h"

#include <ceres/ceres.h>
#include <ceres/product_manifold.h>
#include <ceres/rotation.h>

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <array>
#include <cmath>

#include "core/median.h"

namespace mocap::rigcal {
namespace {

struct WandReprojection {
  Vec2 obs;
  double offset_mm;
  Eigen::Matrix2d weight;  // W, W^T W = the centre's relative information (identity: none)
  template <class T>
  bool operator()(const T* intr, const T* pose, const T* wand, T* res) const {
    const T* A = wand;
    const T* d = wand + 3;
    T X[3] = {A[0] + offset_mm * d[0], A[1] + offset_mm * d[1], A[2] + offset_mm * d[2]};
    T Xc[3];
    ceres::AngleAxisRotatePoint(pose, X, Xc);
    Xc[0] += pose[3];
    Xc[1] += pose[4];
    Xc[2] += pose[5];
    if (Xc[2] <= T(1e-9)) return false;
    const T x = Xc[0] / Xc[2], y = Xc[1] / Xc[2];
    const T r2 = x * x + y * y;
    const T radial = T(1) + intr[4] * r2 + intr[5] * r2 * r2 + intr[8] * r2 * r2 * r2;
    const T xd = x * radial + T(2) * intr[6] * x * y + intr[7] * (r2 + T(2) * x * x);
    const T yd = y * radial + intr[6] * (r2 + T(2) * y * y) + T(2) * intr[7] * x * y;
    const T ex = intr[0] * xd + intr[2] - obs.x(), ey = intr[1] * yd + intr[3] - obs.y();
    res[0] = weight(0, 0) * ex + weight(0, 1) * ey;
    res[1] = weight(1, 0) * ex + weight(1, 1) * ey;
    return true;
  }
};

std::array<double, 9> intrinsics_of(const CameraModel& c) {
  return {c.fx,
          c.fy,
          c.cx,
          c.cy,
          c.distortion[0],
          c.distortion[1],
          c.distortion[2],
          c.distortion[3],
          c.distortion[4]};
}

void set_intrinsics(CameraModel& c, const std::array<double, 9>& p) {
  c.fx = p[0];
  c.fy = p[1];
  c.cx = p[2];
  c.cy = p[3];
  for (std::size_t i = 0; i < 5; ++i) c.distortion[i] = p[4 + i];
}

std::array<double, 6> pose_of(const CameraModel& c) {
  std::array<double, 6> p{};
  Eigen::AngleAxisd aa(c.R_cam_world);
  const Vec3 v = aa.angle() * aa.axis();
  p = {v.x(), v.y(), v.z(), c.t_cam_world.x(), c.t_cam_world.y(), c.t_cam_world.z()};
  return p;
}

void set_pose(CameraModel& c, const std::array<double, 6>& p) {
  const Vec3 v(p[0], p[1], p[2]);
  const double a = v.norm();
  c.R_cam_world =
      a > 0.0 ? Mat3(Eigen::AngleAxisd(a, v / a).toRotationMatrix()) : Mat3(Mat3::Identity());
  c.t_cam_world = Vec3(p[3], p[4], p[5]);
}

// A centre's weight relative to the median centre of the recording's labelled views:
// W with W^T W = s2 cov^-1, s2 the median of the covariances' mean variance. A centre
// without a covariance weighs as the median. Variances are floored at s2 / 4 (a
// centre at most twice as precise as the median): the fit's own covariance rests on
// the residuals of 32..64 edge points and a lucky fit must not outweigh its rays.
std::vector<std::vector<std::vector<Eigen::Matrix2d>>> centre_weights(
    const std::vector<WandFrame>& frames, std::size_t markers, bool enabled) {
  std::vector<double> v;
  for (const WandFrame& f : frames)
    for (const auto& cam : f.info)
      for (const CentreInfo& c : cam)
        if (c.cov_px2.trace() > 0.0) v.push_back(0.5 * c.cov_px2.trace());
  std::vector<std::vector<std::vector<Eigen::Matrix2d>>> out(frames.size());
  double s2 = 0.0;
  if (enabled && !v.empty()) s2 = median_in_place(v);
  for (std::size_t f = 0; f < frames.size(); ++f) {
    out[f].assign(frames[f].px.size(),
                  std::vector<Eigen::Matrix2d>(markers, Eigen::Matrix2d::Identity()));
    if (!(s2 > 0.0)) continue;
    for (std::size_t c = 0; c < frames[f].info.size() && c < frames[f].px.size(); ++c) {
      for (std::size_t k = 0; k < markers && k < frames[f].info[c].size(); ++k) {
        const Eigen::Matrix2d& cov = frames[f].info[c][k].cov_px2;
        if (!(cov.trace() > 0.0)) continue;
        Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> es(cov / s2);
        const Eigen::Vector2d lambda = es.eigenvalues().cwiseMax(0.25);
        // W = diag(lambda)^-1/2 V^T: W^T W = V diag(lambda)^-1 V^T.
        out[f][c][k] =
            lambda.cwiseSqrt().cwiseInverse().asDiagonal() * es.eigenvectors().transpose();
      }
    }
  }
  return out;
}

}  // namespace

int WandFrame::cameras_labelled() const noexcept {
  int n = 0;
  for (const auto& p : px) n += p.empty() ? 0 : 1;
  return n;
}

bool wand_residuals(const std::vector<CameraModel>& cams, const WandSpec& wand,
                    const WandFrame& obs, const WandPose& pose,
                    const std::vector<std::vector<Eigen::Matrix2d>>& weight,
                    std::vector<WandResidual>& out) {
  out.clear();
  for (std::size_t c = 0; c < cams.size() && c < obs.px.size(); ++c) {
    if (obs.px[c].empty()) continue;
    for (std::size_t k = 0; k < wand.markers_mm.size() && k < obs.px[c].size(); ++k) {
      const Vec3 X = pose.A + (wand.markers_mm[k] - wand.markers_mm[0]) * pose.d;
      Vec2 px;
      if (!project(cams[c], X, px)) return false;
      const Vec2 e = px - obs.px[c][k];
      WandResidual r;
      r.px = e.norm();
      r.weighted = c < weight.size() && k < weight[c].size() ? (weight[c][k] * e).norm() : r.px;
      r.camera = static_cast<int>(c);
      r.partly_hidden =
          c < obs.info.size() && k < obs.info[c].size() && obs.info[c][k].partly_hidden;
      out.push_back(r);
    }
  }
  return true;
}

Expected<BundleStats> bundle_adjust(const WandSpec& wand, const std::vector<WandFrame>& frames,
                                    std::vector<bool>& use, std::vector<CameraModel>& cams,
                                    std::vector<WandPose>& poses, const BundleOptions& options) {
  if (frames.size() != poses.size() || frames.size() != use.size())
    return make_error("bundle", "", "frames, poses and flags differ in size");
  const std::size_t C = cams.size();
  if (C < 2) return make_error("bundle", "cameras", "needs at least two cameras");
  if (!options.refine_camera.empty() && options.refine_camera.size() != C)
    return make_error("bundle", "refine_camera", "one flag per camera expected");
  for (std::size_t f = 0; f < frames.size(); ++f) {
    if (frames[f].px.size() != C)
      return make_error("bundle", "frame " + std::to_string(frames[f].frame),
                        "observations of " + std::to_string(frames[f].px.size()) +
                            " cameras, the rig has " + std::to_string(C));
    if (frames[f].cameras_labelled() < 2) use[f] = false;
  }
  BundleStats stats;
  std::vector<WandResidual> err;
  const auto weights = centre_weights(frames, wand.markers_mm.size(), options.weight_by_covariance);
  for (int round = 0; round < std::max(1, options.rounds); ++round) {
    std::vector<std::array<double, 9>> intr(C);
    std::vector<std::array<double, 6>> pose(C);
    for (std::size_t c = 0; c < C; ++c) {
      intr[c] = intrinsics_of(cams[c]);
      pose[c] = c == 0 ? std::array<double, 6>{} : pose_of(cams[c]);
    }
    std::vector<bool> observed(C, false);
    std::vector<std::array<double, 6>> W(frames.size());
    ceres::Problem problem;
    auto* loss = new ceres::HuberLoss(options.huber_px);
    auto* ordering = new ceres::ParameterBlockOrdering;
    int used = 0;
    for (std::size_t f = 0; f < frames.size(); ++f) {
      if (!use[f]) continue;
      ++used;
      const Vec3 dn = poses[f].d.normalized();
      W[f] = {poses[f].A.x(), poses[f].A.y(), poses[f].A.z(), dn.x(), dn.y(), dn.z()};
      for (std::size_t c = 0; c < C; ++c) {
        if (frames[f].px[c].empty()) continue;
        observed[c] = true;
        for (std::size_t k = 0; k < wand.markers_mm.size(); ++k) {
          auto* cost =
              new ceres::AutoDiffCostFunction<WandReprojection, 2, 9, 6, 6>(new WandReprojection{
                  frames[f].px[c][k], wand.markers_mm[k] - wand.markers_mm[0], weights[f][c][k]});
          problem.AddResidualBlock(cost, loss, intr[c].data(), pose[c].data(), W[f].data());
        }
      }
      problem.SetManifold(
          W[f].data(),
          new ceres::ProductManifold<ceres::EuclideanManifold<3>, ceres::SphereManifold<3>>(
              ceres::EuclideanManifold<3>(), ceres::SphereManifold<3>()));
      ordering->AddElementToGroup(W[f].data(), 0);
    }
    if (used < 8) {
      delete ordering;
      return make_error("bundle", "",
                        "only " + std::to_string(used) + " usable wand frames (need at least 8)");
    }
    for (std::size_t c = 1; c < C; ++c) {
      if (!observed[c]) {
        delete ordering;
        return make_error("bundle", cams[c].name, "no usable wand frame sees this camera");
      }
    }
    for (std::size_t c = 0; c < C; ++c) {
      if (!observed[c]) continue;  // camera 0 only: the gauge needs no residual
      if (c == 0) problem.SetParameterBlockConstant(pose[c].data());
      const bool refine =
          options.refine_camera.empty() ? options.refine_intrinsics : options.refine_camera[c];
      if (refine) {
        problem.SetManifold(intr[c].data(), new ceres::SubsetManifold(9, {6, 7, 8}));
      } else {
        problem.SetParameterBlockConstant(intr[c].data());
      }
      ordering->AddElementToGroup(intr[c].data(), 1);
      ordering->AddElementToGroup(pose[c].data(), 1);
    }
    ceres::Solver::Options so;
    so.linear_solver_type = ceres::DENSE_SCHUR;
    so.linear_solver_ordering.reset(ordering);
    so.max_num_iterations = options.max_iterations;
    so.function_tolerance = 1e-12;
    so.gradient_tolerance = 1e-12;
    so.parameter_tolerance = 1e-12;
    so.num_threads = 1;
    so.logging_type = ceres::SILENT;
    ceres::Solver::Summary summary;
    ceres::Solve(so, &problem, &summary);
    stats.iterations += static_cast<int>(summary.iterations.size());
    stats.converged = summary.termination_type == ceres::CONVERGENCE;
    if (!summary.IsSolutionUsable())
      return make_error("bundle", "", "Ceres failed: " + summary.message);
    for (std::size_t c = 0; c < C; ++c) {
      set_intrinsics(cams[c], intr[c]);
      if (c > 0) set_pose(cams[c], pose[c]);
    }
    for (std::size_t f = 0; f < frames.size(); ++f) {
      if (!use[f]) continue;
      poses[f].A = Vec3(W[f][0], W[f][1], W[f][2]);
      poses[f].d = Vec3(W[f][3], W[f][4], W[f][5]).normalized();
    }
    // Drop outlier frames before the next round.
    // The threshold adapts to the noise: outlier_sigmas x the RMS residual, clamped to
    // [outlier_min_px, outlier_px].
    if (round + 1 < options.rounds) {
      double ss = 0.0;
      int count = 0;
      for (std::size_t f = 0; f < frames.size(); ++f) {
        if (!use[f] || !wand_residuals(cams, wand, frames[f], poses[f], weights[f], err)) continue;
        for (const WandResidual& e : err) {
          ss += e.weighted * e.weighted;
          ++count;
        }
      }
      const double rms = count > 0 ? std::sqrt(ss / count) : 0.0;
      const double limit =
          std::clamp(options.outlier_sigmas * rms, options.outlier_min_px, options.outlier_px);
      for (std::size_t f = 0; f < frames.size(); ++f) {
        if (!use[f]) continue;
        if (!wand_residuals(cams, wand, frames[f], poses[f], weights[f], err)) {
          use[f] = false;
          continue;
        }
        for (const WandResidual& e : err) {
          if (e.weighted > limit) use[f] = false;
        }
      }
    }
  }
  // Statistics over the frames in use: per camera over the whole balls, or over all
  // when a camera has none (a partly hidden ball's noise says little of the rig).
  std::vector<double> sum(C, 0.0), sum_all(C, 0.0);
  std::vector<int> count(C, 0), count_all(C, 0);
  stats.frames_per_camera.assign(C, 0);
  stats.frames_used = 0;
  for (std::size_t f = 0; f < frames.size(); ++f) {
    if (!use[f]) {
      ++stats.frames_dropped;
      continue;
    }
    ++stats.frames_used;
    for (std::size_t c = 0; c < C; ++c)
      stats.frames_per_camera[c] += frames[f].px[c].empty() ? 0 : 1;
    if (!wand_residuals(cams, wand, frames[f], poses[f], weights[f], err)) continue;
    for (const WandResidual& e : err) {
      const auto c = static_cast<std::size_t>(e.camera);
      sum_all[c] += e.px * e.px;
      ++count_all[c];
      if (e.partly_hidden) continue;
      sum[c] += e.px * e.px;
      ++count[c];
    }
  }
  stats.rms_px.assign(C, 0.0);
  for (std::size_t c = 0; c < C; ++c) {
    stats.rms_px[c] = count[c] > 0       ? std::sqrt(sum[c] / count[c])
                      : count_all[c] > 0 ? std::sqrt(sum_all[c] / count_all[c])
                                         : 0.0;
  }
  return stats;
}

}  // namespace mocap::rigcal
