// Design: see chain_solver.h. Joints whose child was found by identification, its parent
// found too or solved through the chain: the calibrated joint is a measurement too. The parent's
// pose predicts where the joint centre is (T_world_parent * c_parent, with the covariance of the
// parent's fit carried to the centre, plus the model's centre error); the child's pose
// must put its own c_child there. Per joint, from the roots down:
//  - ball: the child's pose is refitted on its labelled markers (weights 1/sigma^2) plus
//    the predicted centre as one more point with its full covariance (6-dof Gauss-Newton
//    from the identified pose), dropping the child's worst marker while the test fails
//    and 3 remain. A hand's 3-4 markers span a few cm; the wrist centre
//    8 cm away fixes the rotation that their spread leaves loose.
//  - hinge: the centre agreement alone is tested (the axis already fixes 2 of the 3
//    rotations, and its two bodies are long: the refit would change little).
// Either way the chi-square test (3 (m + 1) - 6 degrees of freedom for the refit, 3 for
// the hinge's centre) at `confidence` decides: a joint whose two poses disagree with the
// joint beyond the noise is not valid (pose_rejects) — one of the poses is wrong, and
// an angle from it would be too. Standard deviations: the refit's rotation covariance
// plus the parent's, in the parent's frame.
#include <cmath>

#include "core/rotation.h"
#include "identify/consistency.h"
#include "track/chain_solver.h"

namespace mocap {
namespace {

Mat3 skew3(const Vec3& v) noexcept {
  Mat3 S;
  S << 0.0, -v.z(), v.y(), v.z(), 0.0, -v.x(), -v.y(), v.x(), 0.0;
  return S;
}

}  // namespace

Mat3 ChainSolver::centre_cov(int b, const Vec3& c_world, const BodyPoses& poses,
                             const ChainResult& out) const noexcept {
  // Translation noise of the fit at its markers' centroid, plus its rotation noise over
  // the lever to the centre, plus the calibrated centre's own error.
  const auto ub = static_cast<std::size_t>(b);
  const bool chain = out.chain_body[ub];
  const auto& labels = chain || out.refined_body[ub] ? out.point_index_of_marker[ub]
                                                     : poses.bodies[ub].point_index_of_marker;
  const Iso3& T =
      chain || out.refined_body[ub] ? out.T_world_body[ub] : poses.bodies[ub].T_world_body;
  const std::vector<Vec3>& markers = model_.markers(b);
  Vec3 mean = Vec3::Zero();
  int m = 0;
  for (std::size_t k = 0; k < markers.size(); ++k)
    if (labels[k] >= 0) mean += markers[k], ++m;
  const double s2 = config_.point_sigma_mm * config_.point_sigma_mm;
  const double c2 = config_.centre_sigma_mm * config_.centre_sigma_mm;
  if (m == 0) return Mat3::Identity() * 1e6;
  mean = T * (mean / m);
  const Mat3 L = skew3(c_world - mean);
  return (s2 / m + c2) * Mat3::Identity() + L * body_cov(b, poses, out) * L.transpose();
}

bool ChainSolver::refit_child(int j, const Vec3& c_w, const Mat3& W_c, const MeasuredPoint* pts,
                              int n, const BodyPose& child,
                              std::array<std::int16_t, kMaxMarkers>& labels, Iso3& T_wc,
                              Mat3& cov_R) const noexcept {
  const ChainJoint& cj = model_.joint(j);
  const std::vector<Vec3>& markers = model_.markers(cj.child);
  labels = child.point_index_of_marker;
  for (std::size_t k = 0; k < markers.size(); ++k)
    if (labels[k] >= n) labels[k] = -1;
  // Drop the worst marker while the test fails and 3 remain (the centre is never
  // dropped: when it is the worst, the two poses disagree).
  for (int round = 0; round < kMaxMarkers; ++round) {
    Mat3 R = child.T_world_body.linear();
    Vec3 t = child.T_world_body.translation();
    Eigen::Matrix<double, 6, 6> H;
    double chi2 = 0.0, worst = -1.0, centre_e = 0.0;
    int m = 0, worst_k = -1;
    for (int iter = 0; iter < 5; ++iter) {
      H.setZero();
      Eigen::Matrix<double, 6, 1> g = Eigen::Matrix<double, 6, 1>::Zero();
      chi2 = 0.0;
      worst = -1.0;
      m = 0;
      const auto add = [&](const Vec3& x_body, const Vec3& meas, const Mat3& W) {
        const Vec3 Rx = R * x_body;
        const Vec3 r = Rx + t - meas;
        Eigen::Matrix<double, 3, 6> J;
        J.leftCols<3>() = -skew3(Rx);
        J.rightCols<3>() = Mat3::Identity();
        H += J.transpose() * W * J;
        g += J.transpose() * W * r;
        const double e = r.dot(W * r);
        chi2 += e;
        return e;
      };
      for (std::size_t k = 0; k < markers.size(); ++k) {
        const int p = labels[k];
        if (p < 0) continue;
        const double e = add(markers[k], pts[p].X_world, Mat3::Identity() / sigma_sq(p, pts[p]));
        if (e > worst) worst = e, worst_k = static_cast<int>(k);
        ++m;
      }
      centre_e = add(cj.c_child, c_w, W_c);
      if (m < 3) return false;
      const Eigen::LDLT<Eigen::Matrix<double, 6, 6>> ldlt(H);
      if (ldlt.info() != Eigen::Success) return false;
      const Eigen::Matrix<double, 6, 1> step = ldlt.solve(-g);
      if (!step.allFinite()) return false;
      const double a = step.head<3>().norm();
      const Mat3 dR =
          a > 1e-15 ? Mat3(Eigen::AngleAxisd(a, step.head<3>() / a)) : Mat3(Mat3::Identity());
      R = dR * R;
      t = dR * t + step.tail<3>();
      if (step.cwiseAbs().maxCoeff() < 1e-10) break;
    }
    if (chi2 <= chi2_quantile(3 * (m + 1) - 6, config_.confidence)) {
      T_wc = Iso3::Identity();
      T_wc.linear() = R;
      T_wc.translation() = t;
      cov_R = H.ldlt().solve(Eigen::Matrix<double, 6, 6>::Identity()).topLeftCorner<3, 3>();
      return true;
    }
    if (m <= 3 || centre_e >= worst || worst_k < 0) return false;
    labels[static_cast<std::size_t>(worst_k)] = -1;
  }
  return false;
}

void ChainSolver::check_pose_joints(const MeasuredPoint* pts, int n, const BodyPoses& poses,
                                    ChainResult& out) noexcept {
  const int nb = std::min(model_.body_count(), poses.count);
  const auto reject = [&](std::size_t uj) {
    out.joints[uj] = ChainJointResult{client::SolvedBy::kNone, {}, true};
    ++counters_.pose_rejects;
  };
  for (const int j : model_.order()) {
    const auto uj = static_cast<std::size_t>(j);
    if (out.joints[uj].solved_by == client::SolvedBy::kNone) continue;
    const ChainJoint& cj = model_.joint(j);
    if (cj.parent >= nb || cj.child >= nb) continue;
    const auto up = static_cast<std::size_t>(cj.parent);
    const auto uc = static_cast<std::size_t>(cj.child);
    const BodyPose& child = poses.bodies[uc];
    // The child found by identification, its parent found or solved through the chain.
    if (!child.found || out.chain_body[uc]) continue;
    const Iso3& T_wp = out.chain_body[up] || out.refined_body[up] ? out.T_world_body[up]
                                                                  : poses.bodies[up].T_world_body;
    const Vec3 c_w = T_wp * cj.c_parent;
    const Mat3 cov_c = centre_cov(cj.parent, c_w, poses, out);
    const Mat3 R_wp = T_wp.linear();
    if (cj.dof == 1) {
      // Hinge: the two poses' centres must agree.
      const Vec3 d = c_w - child.T_world_body * cj.c_child;
      const Mat3 cov = cov_c + centre_cov(cj.child, child.T_world_body * cj.c_child, poses, out);
      const Eigen::LDLT<Mat3> ldlt(cov);
      if (ldlt.info() != Eigen::Success ||
          !(d.dot(ldlt.solve(d)) <= chi2_quantile(3, config_.confidence))) {
        reject(uj);
      } else if (out.refined_body[up]) {
        // The parent was refitted: its (smaller) rotation covariance.
        const Mat3 cov_rel = R_wp.transpose() *
                             (body_cov(cj.parent, poses, out) + body_cov(cj.child, poses, out)) *
                             R_wp;
        out.joints[uj].sd_rad = {
            std::sqrt(std::max(0.0, cj.axis_parent.dot(cov_rel * cj.axis_parent))), 0.0, 0.0};
      }
      continue;
    }
    // Ball: refit the child with the centre as one more measured point.
    const Eigen::LDLT<Mat3> cl(cov_c);
    if (cl.info() != Eigen::Success) continue;
    std::array<std::int16_t, kMaxMarkers> labels{};
    Iso3 T_wc;
    Mat3 cov_R;
    if (!refit_child(j, c_w, cl.solve(Mat3::Identity()), pts, n, child, labels, T_wc, cov_R)) {
      reject(uj);
      continue;
    }
    // A body that anchors a chain-solved joint keeps the pose that joint was solved from
    // (the test above still applies).
    bool anchors_chain = false;
    for (int k = 0; k < model_.joint_count(); ++k)
      anchors_chain = anchors_chain ||
                      (active_[static_cast<std::size_t>(k)] && model_.joint(k).parent == cj.child);
    if (anchors_chain) continue;
    out.refined_body[uc] = true;
    out.T_world_body[uc] = T_wc;
    out.point_index_of_marker[uc] = labels;
    int m = 0;
    double ss = 0.0;
    const std::vector<Vec3>& markers = model_.markers(cj.child);
    for (std::size_t k = 0; k < markers.size(); ++k) {
      if (labels[k] < 0) continue;
      ss += (T_wc * markers[k] - pts[labels[k]].X_world).squaredNorm();
      ++m;
    }
    out.markers[uc] = m;
    out.rms_mm[uc] = m > 0 ? std::sqrt(ss / m) : 0.0;
    refined_cov_[uc] = cov_R;
    const Mat3 cov = R_wp.transpose() * (cov_R + body_cov(cj.parent, poses, out)) * R_wp;
    out.joints[uj].sd_rad = chain_detail::euler_sd(R_wp.transpose() * T_wc.linear(), cov);
    ++counters_.pose_refits;
  }
}

}  // namespace mocap
