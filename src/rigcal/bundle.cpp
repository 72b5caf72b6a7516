// Design: see bundle.h.
#include "rigcal/bundle.h"

#include <ceres/ceres.h>
#include <ceres/product_manifold.h>
#include <ceres/rotation.h>

#include <algorithm>
#include <cmath>

namespace mocap::rigcal {
namespace {

struct WandReprojection {
  Vec2 obs;
  double offset_mm;
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
    res[0] = intr[0] * xd + intr[2] - obs.x();
    res[1] = intr[1] * yd + intr[3] - obs.y();
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

}  // namespace

bool wand_residuals(const std::array<CameraModel, 2>& cams, const WandSpec& wand,
                    const WandFrame& obs, const WandPose& pose, std::vector<double>& err_px) {
  err_px.clear();
  for (std::size_t c = 0; c < 2; ++c) {
    for (std::size_t k = 0; k < wand.markers_mm.size(); ++k) {
      const Vec3 X = pose.A + (wand.markers_mm[k] - wand.markers_mm[0]) * pose.d;
      Vec2 px;
      if (!project(cams[c], X, px)) return false;
      err_px.push_back((px - obs.px[c][k]).norm());
    }
  }
  return true;
}

Expected<BundleStats> bundle_adjust(const WandSpec& wand, const std::vector<WandFrame>& frames,
                                    std::vector<bool>& use, std::array<CameraModel, 2>& cams,
                                    std::vector<WandPose>& poses, const BundleOptions& options) {
  if (frames.size() != poses.size() || frames.size() != use.size())
    return make_error("bundle", "", "frames, poses and flags differ in size");
  BundleStats stats;
  std::vector<double> err;
  for (int round = 0; round < std::max(1, options.rounds); ++round) {
    std::array<std::array<double, 9>, 2> intr = {intrinsics_of(cams[0]), intrinsics_of(cams[1])};
    std::array<std::array<double, 6>, 2> pose = {std::array<double, 6>{}, pose_of(cams[1])};
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
      for (std::size_t c = 0; c < 2; ++c) {
        for (std::size_t k = 0; k < wand.markers_mm.size(); ++k) {
          auto* cost = new ceres::AutoDiffCostFunction<WandReprojection, 2, 9, 6, 6>(
              new WandReprojection{frames[f].px[c][k], wand.markers_mm[k] - wand.markers_mm[0]});
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
    problem.SetParameterBlockConstant(pose[0].data());
    for (std::size_t c = 0; c < 2; ++c) {
      if (options.refine_intrinsics) {
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
    for (std::size_t c = 0; c < 2; ++c) {
      set_intrinsics(cams[c], intr[c]);
      if (c == 1) set_pose(cams[c], pose[c]);
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
        if (!use[f] || !wand_residuals(cams, wand, frames[f], poses[f], err)) continue;
        for (double e : err) {
          ss += e * e;
          ++count;
        }
      }
      const double rms = count > 0 ? std::sqrt(ss / count) : 0.0;
      const double limit =
          std::clamp(options.outlier_sigmas * rms, options.outlier_min_px, options.outlier_px);
      for (std::size_t f = 0; f < frames.size(); ++f) {
        if (!use[f]) continue;
        if (!wand_residuals(cams, wand, frames[f], poses[f], err)) {
          use[f] = false;
          continue;
        }
        for (double e : err) {
          if (e > limit) use[f] = false;
        }
      }
    }
  }
  // Statistics over the frames in use.
  std::array<double, 2> sum{};
  std::array<int, 2> count{};
  stats.frames_used = 0;
  for (std::size_t f = 0; f < frames.size(); ++f) {
    if (!use[f]) {
      ++stats.frames_dropped;
      continue;
    }
    ++stats.frames_used;
    if (!wand_residuals(cams, wand, frames[f], poses[f], err)) continue;
    const std::size_t N = wand.markers_mm.size();
    for (std::size_t i = 0; i < err.size(); ++i) {
      sum[i / N] += err[i] * err[i];
      ++count[i / N];
    }
  }
  for (std::size_t c = 0; c < 2; ++c)
    stats.rms_px[c] = count[c] > 0 ? std::sqrt(sum[c] / count[c]) : 0.0;
  return stats;
}

}  // namespace mocap::rigcal
