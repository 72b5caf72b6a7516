// Design: see chain_solver.h. The per-frame driver of chain tracking: anchors and
// available points, labelling from the roots, the solve/test/drop loop, and every
// joint's solved-by flag and standard deviations.
#include <Eigen/Eigenvalues>
#include <Eigen/LU>
#include <algorithm>
#include <bit>
#include <cmath>
#include <cstring>
#include <numbers>

#include "core/rotation.h"
#include "identify/consistency.h"
#include "track/chain_solver.h"

namespace mocap {
namespace {

constexpr std::size_t kBlobBits = 4096;  // blobs beyond this index are not ghost-checked
constexpr std::size_t kBlobWords = kBlobBits / 64;

Mat3 exp_hinge(const Vec3& axis, double a) noexcept {
  return Eigen::AngleAxisd(a, axis).toRotationMatrix();
}

}  // namespace

// Euler-angle standard deviations for a rotation increment covariance (parent frame).
std::array<double, 3> chain_detail::euler_sd(const Mat3& R, const Mat3& cov) noexcept {
  constexpr double h = 1e-6;
  Mat3 J;
  for (int k = 0; k < 3; ++k) {
    const Vec3 e = Vec3::Unit(k);
    Vec3 diff =
        rotation_to_euler_xyz(exp_hinge(e, h) * R) - rotation_to_euler_xyz(exp_hinge(e, -h) * R);
    for (int i = 0; i < 3; ++i) diff[i] = std::remainder(diff[i], 2.0 * std::numbers::pi);
    J.col(k) = diff / (2.0 * h);
  }
  const Mat3 C = J * cov * J.transpose();
  return {std::sqrt(std::max(0.0, C(0, 0))), std::sqrt(std::max(0.0, C(1, 1))),
          std::sqrt(std::max(0.0, C(2, 2)))};
}

void ChainSolver::solve(const MeasuredPoint* pts, int n, std::int64_t t_ns, const BodyPoses& poses,
                        ChainResult& out, const double* partial_sigma_mm) noexcept {
  ++counters_.frames;
  n = std::clamp(n, 0, kMaxPoints);
  partial_sigma_mm_ = partial_sigma_mm;
  partial_sigma_count_ = n;
  const int nj = model_.joint_count();
  const int nb = std::min(model_.body_count(), poses.count);
  for (int j = 0; j < nj; ++j) {
    out.joints[static_cast<std::size_t>(j)] = ChainJointResult{};
    active_[static_cast<std::size_t>(j)] = false;
  }
  for (std::size_t b = 0; b < kMaxBodies; ++b) {
    out.chain_body[b] = false;
    out.refined_body[b] = false;
    out.markers[b] = 0;
    out.rms_mm[b] = 0.0;
    out.point_index_of_marker[b].fill(-1);
  }
  const auto found = [&](int b) { return poses.bodies[static_cast<std::size_t>(b)].found; };
  const auto anchored = [&](int b) {
    return found(b) || out.chain_body[static_cast<std::size_t>(b)];
  };
  const auto pose_of = [&](int b) -> const Iso3& {
    const auto ub = static_cast<std::size_t>(b);
    return out.chain_body[ub] ? out.T_world_body[ub] : poses.bodies[ub].T_world_body;
  };

  if (config_.enabled && nj > 0) {
    // 1. Points of found bodies, and their epipolar ghosts, are not available.
    // One row of kBlobBits bits per camera, up to the highest camera a point uses (only
    // those rows are cleared: an 8-camera rig clears what it did with 8 possible cameras).
    CameraMask seen = 0;
    for (int p = 0; p < n; ++p) seen |= pts[p].blob_index.mask();
    std::uint64_t used_blob[kMaxCameras][kBlobWords];
    std::memset(used_blob, 0,
                sizeof(used_blob[0]) * static_cast<std::size_t>(std::bit_width(seen)));
    const auto take = [&](int p) {
      available_[static_cast<std::size_t>(p)] = false;
      pts[p].blob_index.for_each([&](int c, int bi) {
        if (static_cast<std::size_t>(bi) < kBlobBits)
          used_blob[c][bi >> 6] |= std::uint64_t{1} << (bi & 63);
      });
    };
    for (int p = 0; p < n; ++p)
      available_[static_cast<std::size_t>(p)] = pts[p].X_world.allFinite();
    for (int b = 0; b < nb; ++b) {
      if (!found(b)) continue;
      for (const std::int16_t p : poses.bodies[static_cast<std::size_t>(b)].point_index_of_marker)
        if (p >= 0 && p < n) take(p);
    }
    const auto ghost_check = [&]() {
      for (int p = 0; p < n; ++p) {
        pts[p].blob_index.for_each([&](int c, int bi) {
          if (static_cast<std::size_t>(bi) < kBlobBits &&
              ((used_blob[c][bi >> 6] >> (bi & 63)) & 1u) != 0)
            available_[static_cast<std::size_t>(p)] = false;
        });
      }
    };
    ghost_check();

    // 2-3. Labels and initial angles, from the roots down.
    for (const int j : model_.order()) {
      const ChainJoint& cj = model_.joint(j);
      if (cj.child >= nb || cj.parent >= nb || found(cj.child) || !anchored(cj.parent)) continue;
      ++counters_.attempts;
      const auto uc = static_cast<std::size_t>(cj.child);
      auto& labels = out.point_index_of_marker[uc];
      const Iso3 T_wp = pose_of(cj.parent);
      Mat3 R;
      if (label_child(j, T_wp, pts, n, t_ns, labels) == 0 ||
          !initial_rotation(j, T_wp, pts, labels, t_ns, R)) {
        labels.fill(-1);
        ++counters_.too_few_labels;
        continue;
      }
      const Prior& prior = priors_[static_cast<std::size_t>(j)];
      const double age_s = static_cast<double>(t_ns - prior.t_ns) * 1e-9;
      warm_[static_cast<std::size_t>(j)] =
          prior.valid && age_s > 0.0 && age_s <= config_.max_prior_age_s;
      active_[static_cast<std::size_t>(j)] = true;
      R_rel_[static_cast<std::size_t>(j)] = R;
      out.chain_body[uc] = true;
      out.T_world_body[uc] = T_wp * model_.parent_child(j, R);
      for (const std::int16_t p : labels)
        if (p >= 0) take(p);
      ghost_check();
    }

    // 4-5. Joint solve, chi-square test, drops.
    for (int round = 0; round < kMaxMarkers * kMaxBodies; ++round) {
      bool any = false;
      for (int j = 0; j < nj; ++j) any = any || active_[static_cast<std::size_t>(j)];
      if (!any) break;
      if (!gauss_newton(pts, poses, out)) {
        for (int j = 0; j < nj; ++j)
          if (active_[static_cast<std::size_t>(j)]) deactivate(j, out), ++counters_.chi2_rejects;
        break;
      }
      if (dof_ > 0 && chi2_ > chi2_quantile(dof_, config_.confidence)) {
        // Drop the marker with the largest normalised residual, then the joints left
        // without enough markers.
        double worst = -1.0;
        int wb = -1, wm = -1;
        for (int b = 0; b < nb; ++b) {
          const auto ub = static_cast<std::size_t>(b);
          if (!out.chain_body[ub]) continue;
          const std::vector<Vec3>& markers = model_.markers(b);
          for (std::size_t m = 0; m < markers.size(); ++m) {
            const int p = out.point_index_of_marker[ub][m];
            if (p < 0) continue;
            const double e = (out.T_world_body[ub] * markers[m] - pts[p].X_world).squaredNorm() /
                             sigma_sq(p, pts[p]);
            if (e > worst) worst = e, wb = b, wm = static_cast<int>(m);
          }
        }
        if (wb < 0) break;
        out.point_index_of_marker[static_cast<std::size_t>(wb)][static_cast<std::size_t>(wm)] = -1;
        ++counters_.chi2_drops;
        for (const int j : model_.order()) {
          const auto uj = static_cast<std::size_t>(j);
          if (!active_[uj]) continue;
          const ChainJoint& cj = model_.joint(j);
          int left = 0;
          for (const std::int16_t p : out.point_index_of_marker[static_cast<std::size_t>(cj.child)])
            left += p >= 0 ? 1 : 0;
          const int needed = (cj.dof == 1 ? 1 : 2) + (warm_[uj] ? 0 : 1);
          if (left < needed) deactivate(j, out), ++counters_.chi2_rejects;
        }
        continue;
      }
      bool dropped = false;
      for (int j = 0; j < nj; ++j) {
        if (!active_[static_cast<std::size_t>(j)]) continue;
        // The rotation's largest standard deviation (free of the Euler convention, whose
        // component sds grow near gimbal lock however well the rotation is known).
        const auto uj = static_cast<std::size_t>(j);
        const double sd = model_.joint(j).dof == 1
                              ? sd_dof_[static_cast<std::size_t>(dof_offset_[uj])]
                              : std::sqrt(std::max(0.0, Eigen::SelfAdjointEigenSolver<Mat3>(
                                                            cov_[uj], Eigen::EigenvaluesOnly)
                                                            .eigenvalues()
                                                            .maxCoeff()));
        if (sd > config_.max_sd_deg * std::numbers::pi / 180.0) {
          deactivate(j, out);
          ++counters_.uncertain_rejects;
          dropped = true;
        }
      }
      if (!dropped) break;
    }
    for (int j = 0; j < nj; ++j) {
      const auto uj = static_cast<std::size_t>(j);
      if (!active_[uj]) continue;
      out.joints[uj] = ChainJointResult{client::SolvedBy::kChain, active_sd(j)};
      ++counters_.joints_solved;
      const int c = model_.joint(j).child;
      const auto uc = static_cast<std::size_t>(c);
      const std::vector<Vec3>& markers = model_.markers(c);
      double ss = 0.0;
      int m_count = 0;
      for (std::size_t m = 0; m < markers.size(); ++m) {
        const int p = out.point_index_of_marker[uc][m];
        if (p < 0) continue;
        ss += (out.T_world_body[uc] * markers[m] - pts[p].X_world).squaredNorm();
        ++m_count;
      }
      out.markers[uc] = m_count;
      out.rms_mm[uc] = m_count > 0 ? std::sqrt(ss / m_count) : 0.0;
    }
  }

  // Joints not solved through the chain: from the two poses when both are known.
  for (int j = 0; j < nj; ++j) {
    ChainJointResult& r = out.joints[static_cast<std::size_t>(j)];
    if (r.solved_by != client::SolvedBy::kNone) continue;
    const ChainJoint& cj = model_.joint(j);
    if (cj.parent >= nb || cj.child >= nb || !anchored(cj.parent) || !anchored(cj.child)) continue;
    r.solved_by =
        found(cj.parent) && found(cj.child) ? client::SolvedBy::kPoses : client::SolvedBy::kChain;
    const Mat3 R_wp = pose_of(cj.parent).linear();
    const Mat3 R_rel = R_wp.transpose() * pose_of(cj.child).linear();
    const Mat3 cov = R_wp.transpose() *
                     (body_cov(cj.parent, poses, out) + body_cov(cj.child, poses, out)) * R_wp;
    if (cj.dof == 1) {
      r.sd_rad = {std::sqrt(std::max(0.0, cj.axis_parent.dot(cov * cj.axis_parent))), 0.0, 0.0};
    } else {
      r.sd_rad = chain_detail::euler_sd(R_rel, cov);
    }
  }
  if (config_.enabled) check_pose_joints(pts, n, poses, out);
  for (int j = 0; j < nj; ++j) {
    const auto uj = static_cast<std::size_t>(j);
    if (out.joints[uj].solved_by == client::SolvedBy::kPoses) ++counters_.joint_poses[uj];
    if (out.joints[uj].solved_by == client::SolvedBy::kChain) ++counters_.joint_chain[uj];
  }
}

std::array<double, 3> ChainSolver::active_sd(int j) const noexcept {
  const auto uj = static_cast<std::size_t>(j);
  if (model_.joint(j).dof == 1)
    return {sd_dof_[static_cast<std::size_t>(dof_offset_[uj])], 0.0, 0.0};
  return chain_detail::euler_sd(R_rel_[uj], cov_[uj]);
}

void ChainSolver::deactivate(int j, ChainResult& out) noexcept {
  active_[static_cast<std::size_t>(j)] = false;
  const auto uc = static_cast<std::size_t>(model_.joint(j).child);
  out.chain_body[uc] = false;
  out.point_index_of_marker[uc].fill(-1);
  // Descendants lose their anchor.
  for (const int k : model_.order()) {
    if (!active_[static_cast<std::size_t>(k)]) continue;
    if (model_.joint(k).parent == model_.joint(j).child) deactivate(k, out);
  }
}

Mat3 ChainSolver::body_cov(int b, const BodyPoses& poses, const ChainResult& out) const noexcept {
  const auto ub = static_cast<std::size_t>(b);
  const double s2 = config_.point_sigma_mm * config_.point_sigma_mm;
  if (out.refined_body[ub]) return refined_cov_[ub];
  if (!out.chain_body[ub]) {
    // Rigid fit: sigma^2 (sum |r|^2 I - r r^T)^-1, r about the matched markers' centroid.
    const BodyPose& bp = poses.bodies[ub];
    const std::vector<Vec3>& markers = model_.markers(b);
    Vec3 mean = Vec3::Zero();
    int m_count = 0;
    for (std::size_t m = 0; m < markers.size(); ++m)
      if (bp.point_index_of_marker[m] >= 0) mean += markers[m], ++m_count;
    if (m_count < 3) return Mat3::Identity();  // no rotation information: 1 rad^2
    mean /= m_count;
    Mat3 A = Mat3::Zero();
    for (std::size_t m = 0; m < markers.size(); ++m) {
      if (bp.point_index_of_marker[m] < 0) continue;
      const Vec3 r = bp.T_world_body.linear() * (markers[m] - mean);
      A += r.squaredNorm() * Mat3::Identity() - r * r.transpose();
    }
    // A is symmetric positive semi-definite: its closed-form inverse, unless it is
    // singular to rounding (markers on one line).
    Mat3 A_inv;
    double det = 0.0;
    bool invertible = false;
    const double tr = A.trace();
    A.computeInverseAndDetWithCheck(A_inv, det, invertible, 1e-14 * tr * tr * tr);
    return invertible && tr > 0.0 ? Mat3(s2 * A_inv) : Mat3(Mat3::Identity());
  }
  const int j = model_.joint_into(b);
  const ChainJoint& cj = model_.joint(j);
  const Mat3 R_wp = (out.chain_body[static_cast<std::size_t>(cj.parent)]
                         ? out.T_world_body[static_cast<std::size_t>(cj.parent)]
                         : poses.bodies[static_cast<std::size_t>(cj.parent)].T_world_body)
                        .linear();
  Mat3 own;
  if (cj.dof == 1) {
    const Vec3 a = R_wp * cj.axis_parent;
    const double sd = sd_dof_[static_cast<std::size_t>(dof_offset_[static_cast<std::size_t>(j)])];
    own = sd * sd * a * a.transpose();
  } else {
    own = R_wp * cov_[static_cast<std::size_t>(j)] * R_wp.transpose();
  }
  return own + body_cov(cj.parent, poses, out);
}

void ChainSolver::remember(const BodyPoses& poses, std::int64_t t_ns) noexcept {
  for (int j = 0; j < model_.joint_count(); ++j) {
    const ChainJoint& cj = model_.joint(j);
    if (cj.parent >= poses.count || cj.child >= poses.count) continue;
    const BodyPose& p = poses.bodies[static_cast<std::size_t>(cj.parent)];
    const BodyPose& c = poses.bodies[static_cast<std::size_t>(cj.child)];
    if (!p.found || !c.found) continue;
    Prior& prior = priors_[static_cast<std::size_t>(j)];
    prior.valid = true;
    prior.R_parent_child = p.T_world_body.linear().transpose() * c.T_world_body.linear();
    prior.t_ns = t_ns;
  }
}

}  // namespace mocap
