// Design: see chain_solver.h. Joints whose child was found by identification, its parent
// found too or solved through the chain: the calibrated joint is a measurement too. The
// parent's pose predicts where the joint centre is (T_world_parent * c_parent, with the
// covariance of the parent's fit carried to the centre, plus the model's centre error)
// and, for a hinge, the axis direction (the parent's rotation noise carried to it, plus
// the model's axis error). The child's pose is refitted (6-dof Gauss-Newton from the
// identified pose) on its labelled markers, each weighted by its measurement noise alone
// (point or partial sigma: the chain's model error is the centre's and axis's), plus the
// centre as one more point with its full covariance and, for a hinge, the two components
// of the child's axis across the parent's (which must be 0).
// Tests at `confidence`: the weighted sum of squares (3 (m + 1) + 2 [hinge] - 6 degrees of
// freedom) and every term alone: the drop of the sum when it leaves the fit,
// r^T (Sigma - J H^-1 J^T)^-1 r, against chi-square with its own dof. A marker biased
// along the rotation its body's spread leaves loose (a forearm's 5 markers nearly in a
// line: its roll) is mostly absorbed by the body's own fit, which therefore passes
// identification's tests; the joint's evidence holds that rotation and exposes it. The
// worst term is dropped while a test fails and 2 markers remain (2 labels plus the joint
// determine the pose, as for a warm chain joint); when the centre or the axis is the worst,
// the two poses disagree: the joint is not valid (pose_rejects) — one of the poses is
// wrong, and an angle from it would be too. So is a refit whose rotation sd exceeds
// max_sd_deg. Standard deviations: the refit's rotation covariance plus the parent's, in
// the parent's frame.
#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <cmath>
#include <numbers>

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

bool ChainSolver::refit_child(int j, const JointEvidence& ev, const MeasuredPoint* pts, int n,
                              const BodyPose& child, std::array<std::int16_t, kMaxMarkers>& labels,
                              Iso3& T_wc, Mat3& cov_R) const noexcept {
  using Mat6 = Eigen::Matrix<double, 6, 6>;
  using Vec6 = Eigen::Matrix<double, 6, 1>;
  using Jac3 = Eigen::Matrix<double, 3, 6>;
  const ChainJoint& cj = model_.joint(j);
  const std::vector<Vec3>& markers = model_.markers(cj.child);
  labels = child.point_index_of_marker;
  for (std::size_t k = 0; k < markers.size(); ++k)
    if (labels[k] >= n) labels[k] = -1;
  const double q3 = chi2_quantile(3, config_.confidence);
  const double q2 = chi2_quantile(2, config_.confidence);
  // Residual and Jacobian (rotation increment left-multiplied, world frame) at (R, t) of
  // the joint centre.
  const auto centre_term = [&](const Mat3& R, const Vec3& t, Vec3& r, Jac3& J) {
    const Vec3 Rx = R * cj.c_child;
    r = Rx + t - ev.c_w;
    J.leftCols<3>() = -skew3(Rx);
    J.rightCols<3>() = Mat3::Identity();
  };
  // Hinge: the child's axis must lie along the parent's (its components across it are 0).
  const auto axis_term = [&](const Mat3& R, Eigen::Vector2d& r, Eigen::Matrix<double, 2, 6>& J) {
    const Vec3 b = R * cj.axis_child;
    r = ev.U.transpose() * b;
    J.leftCols<3>() = -ev.U.transpose() * skew3(b);
    J.rightCols<3>().setZero();
  };
  // Each marker's weight: its measurement noise alone (constant over the refit).
  std::array<double, kMaxMarkers> w{};
  for (std::size_t k = 0; k < markers.size(); ++k)
    if (labels[k] >= 0) w[k] = 1.0 / point_sigma_sq(labels[k], pts[labels[k]]);
  // Normal equations and weighted sum of squares of every term at (R, t). A marker's
  // Jacobian is [-[a]x, I] with a = R x_k, so J^T J = [[|a|^2 I - a a^T, [a]x], [-[a]x, I]]
  // and J^T r = [a x r; r]: the markers are summed in closed form (the sums of w, w a,
  // w |a|^2 and w a a^T), not as 6x6 products.
  const auto normal = [&](const Mat3& R, const Vec3& t, Mat6& H, Vec6& g, int& m) {
    double chi2 = 0.0, sw = 0.0, swaa = 0.0;
    Vec3 swa = Vec3::Zero(), g_rot = Vec3::Zero(), g_tra = Vec3::Zero();
    Mat3 outer = Mat3::Zero();
    m = 0;
    for (std::size_t k = 0; k < markers.size(); ++k) {
      if (labels[k] < 0) continue;
      const Vec3 a = R * markers[k];
      const Vec3 r = a + t - pts[labels[k]].X_world;
      const double wk = w[k];
      sw += wk;
      swa += wk * a;
      swaa += wk * a.squaredNorm();
      outer.noalias() += (wk * a) * a.transpose();
      g_rot += wk * a.cross(r);
      g_tra += wk * r;
      chi2 += wk * r.squaredNorm();
      ++m;
    }
    H.topLeftCorner<3, 3>() = swaa * Mat3::Identity() - outer;
    H.topRightCorner<3, 3>() = skew3(swa);
    H.bottomLeftCorner<3, 3>() = skew3(swa).transpose();
    H.bottomRightCorner<3, 3>() = sw * Mat3::Identity();
    g.head<3>() = g_rot;
    g.tail<3>() = g_tra;
    Vec3 r;
    Jac3 J;
    centre_term(R, t, r, J);
    H += J.transpose() * ev.W_c * J;
    g += J.transpose() * ev.W_c * r;
    chi2 += r.dot(ev.W_c * r);
    if (ev.hinge) {
      Eigen::Vector2d ra;
      Eigen::Matrix<double, 2, 6> Ja;
      axis_term(R, ra, Ja);
      H += Ja.transpose() * ev.W_a * Ja;
      g += Ja.transpose() * ev.W_a * ra;
      chi2 += ra.dot(ev.W_a * ra);
    }
    return chi2;
  };
  for (int round = 0; round < kMaxMarkers; ++round) {
    Mat3 R = child.T_world_body.linear();
    Vec3 t = child.T_world_body.translation();
    Mat6 H;
    Vec6 g;
    int m = 0;
    double chi2 = 0.0;
    Eigen::LLT<Mat6> llt;
    bool at_pose = false;  // H, g, chi2 and llt belong to (R, t)
    for (int iter = 0; iter < 6; ++iter) {
      chi2 = normal(R, t, H, g, m);
      if (m < 2) return false;
      if (llt.compute(H).info() != Eigen::Success) return false;
      const Vec6 step = llt.solve(-g);
      if (!step.allFinite()) return false;
      if (step.cwiseAbs().maxCoeff() < 1e-10) {
        at_pose = true;
        break;
      }
      const double a = step.head<3>().norm();
      const Mat3 dR =
          a > 1e-15 ? Mat3(Eigen::AngleAxisd(a, step.head<3>() / a)) : Mat3(Mat3::Identity());
      R = dR * R;
      t = dR * t + step.tail<3>();
    }
    if (!at_pose) {
      chi2 = normal(R, t, H, g, m);
      if (llt.compute(H).info() != Eigen::Success) return false;
    }
    const Mat6 C = llt.solve(Mat6::Identity());
    // Each term tested alone: the drop of the sum of squares when it leaves the fit,
    // r^T (Sigma - J C J^T)^-1 r (a biased marker is diluted in the global sum, and the
    // fit absorbs most of it along the directions its spread leaves loose). As a share of
    // its own chi-square quantile; the largest names the worst term.
    double worst = 0.0, joint_worst = 0.0;
    int worst_k = -1;
    Vec3 r;
    Jac3 J;
    // A marker's J C J^T with J = [-[a]x, I]: [a]x C_rr [a]x^T - B - B^T + C_tt,
    // B = [a]x C_rt.
    const Mat3 C_rr = C.topLeftCorner<3, 3>();
    const Mat3 C_rt = C.topRightCorner<3, 3>();
    const Mat3 C_tt = C.bottomRightCorner<3, 3>();
    for (std::size_t k = 0; k < markers.size(); ++k) {
      if (labels[k] < 0) continue;
      const Vec3 a = R * markers[k];
      r = a + t - pts[labels[k]].X_world;
      const Mat3 S_a = skew3(a);
      const Mat3 B = S_a * C_rt;
      const Mat3 S = (1.0 / w[k]) * Mat3::Identity() -
                     (S_a * C_rr * S_a.transpose() - B - B.transpose() + C_tt);
      const double d = r.dot(S.ldlt().solve(r)) / q3;
      if (std::isfinite(d) && d > worst) worst = d, worst_k = static_cast<int>(k);
    }
    centre_term(R, t, r, J);
    const double dc = r.dot((ev.cov_c - J * C * J.transpose()).ldlt().solve(r)) / q3;
    if (std::isfinite(dc)) joint_worst = dc;
    if (ev.hinge) {
      Eigen::Vector2d ra;
      Eigen::Matrix<double, 2, 6> Ja;
      axis_term(R, ra, Ja);
      const double da = ra.dot((ev.cov_a - Ja * C * Ja.transpose()).ldlt().solve(ra)) / q2;
      if (std::isfinite(da)) joint_worst = std::max(joint_worst, da);
    }
    const int dof = 3 * (m + 1) + (ev.hinge ? 2 : 0) - 6;
    if (chi2 <= chi2_quantile(dof, config_.confidence) && worst <= 1.0 && joint_worst <= 1.0) {
      T_wc = Iso3::Identity();
      T_wc.linear() = R;
      T_wc.translation() = t;
      cov_R = C.topLeftCorner<3, 3>();
      return true;
    }
    // The joint's own evidence the worst: the two poses disagree (no drop).
    if (m <= 2 || joint_worst >= worst || worst_k < 0) return false;
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
  // The largest rotation variance within max_sd_deg^2. A covariance's eigenvalues are not
  // negative, so a trace within it settles the test without the eigenvalues.
  const double max_var = std::pow(config_.max_sd_deg * std::numbers::pi / 180.0, 2);
  const auto certain = [max_var](const Mat3& cov) {
    if (cov.trace() <= max_var) return true;
    return Eigen::SelfAdjointEigenSolver<Mat3>(cov, Eigen::EigenvaluesOnly)
               .eigenvalues()
               .maxCoeff() <= max_var;
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
    const Mat3 R_wp = T_wp.linear();
    JointEvidence ev;
    ev.c_w = c_w;
    ev.cov_c = centre_cov(cj.parent, c_w, poses, out);
    const Eigen::LDLT<Mat3> cl(ev.cov_c);
    if (cl.info() != Eigen::Success) continue;
    ev.W_c = cl.solve(Mat3::Identity());
    ev.hinge = cj.dof == 1;
    if (ev.hinge) {
      // The parent's axis, its direction noise from the parent's rotation noise plus the
      // calibrated axis's own error, across the axis (two directions U).
      const Vec3 a_w = R_wp * cj.axis_parent;
      const Vec3 u1 = a_w.unitOrthogonal();
      ev.U.col(0) = u1;
      ev.U.col(1) = a_w.cross(u1);
      const Mat3 A = skew3(a_w);
      const double sa = config_.axis_sigma_deg * std::numbers::pi / 180.0;
      ev.cov_a = ev.U.transpose() * A * body_cov(cj.parent, poses, out) * A.transpose() * ev.U +
                 sa * sa * Eigen::Matrix2d::Identity();
      const Eigen::LDLT<Eigen::Matrix2d> al(ev.cov_a);
      if (al.info() != Eigen::Success) continue;
      ev.W_a = al.solve(Eigen::Matrix2d::Identity());
    }
    std::array<std::int16_t, kMaxMarkers> labels{};
    Iso3 T_wc;
    Mat3 cov_R;
    // Like a chain angle, the refitted pose must be certain enough (with 2 markers left
    // it may not be: markers nearly in line with the centre).
    if (!refit_child(j, ev, pts, n, child, labels, T_wc, cov_R) || !certain(cov_R)) {
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
    if (ev.hinge)
      out.joints[uj].sd_rad = {std::sqrt(std::max(0.0, cj.axis_parent.dot(cov * cj.axis_parent))),
                               0.0, 0.0};
    else
      out.joints[uj].sd_rad = chain_detail::euler_sd(R_wp.transpose() * T_wc.linear(), cov);
    ++counters_.pose_refits;
  }
}

}  // namespace mocap
