// Design: see chain_solver.h. This file holds the per-frame driver, the joint
// Gauss-Newton solve with its chi-square test, and the standard deviations.
#include "track/chain_solver.h"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "core/units.h"
#include "identify/consistency.h"

namespace mocap {
namespace {

using VecX = chain_detail::DofVector;

Mat3 skew(const Vec3& v) noexcept {
  Mat3 S;
  S << 0.0, -v.z(), v.y(), v.z(), 0.0, -v.x(), -v.y(), v.x(), 0.0;
  return S;
}

Mat3 exp_so3(const Vec3& w) noexcept {
  const double a = w.norm();
  if (a < 1e-15) return Mat3::Identity() + skew(w);
  return Eigen::AngleAxisd(a, w / a).toRotationMatrix();
}

}  // namespace

Expected<ChainSolver> ChainSolver::create(ChainModel model, const ChainConfig& config) {
  const auto bad = [](const char* key, const std::string& why) {
    return make_error("chain", key, why);
  };
  if (!(config.point_sigma_mm > 0.0)) return bad("point_sigma_mm", "must be > 0");
  if (!(config.partial_sigma_mm >= 0.0)) return bad("partial_sigma_mm", "must be >= 0");
  if (!(config.model_sigma_mm >= 0.0)) return bad("model_sigma_mm", "must be >= 0");
  if (!(config.gate_sigmas >= 1.0 && config.gate_sigmas <= 10.0))
    return bad("gate_sigmas", "must be in [1, 10]");
  if (!(config.confidence >= 0.99 && config.confidence <= 0.999999))
    return bad("confidence", "must be in [0.99, 0.999999]");
  if (!(config.max_angular_speed_deg_per_s > 0.0))
    return bad("max_angular_speed_deg_per_s", "must be > 0");
  if (!(config.max_prior_age_s > 0.0)) return bad("max_prior_age_s", "must be > 0");
  if (!(config.max_sd_deg > 0.0)) return bad("max_sd_deg", "must be > 0");
  if (!(config.axis_sigma_deg > 0.0)) return bad("axis_sigma_deg", "must be > 0");
  if (config.max_search_nodes < 16) return bad("max_search_nodes", "must be >= 16");
  if (model.joint_count() > kMaxBodies)
    return make_error("model.yaml", "joints",
                      std::to_string(model.joint_count()) +
                          " joints, chain tracking supports at most " + std::to_string(kMaxBodies));
  return ChainSolver(std::move(model), config);
}

ChainSolver::ChainSolver(ChainModel model, const ChainConfig& config)
    : model_(std::move(model)), config_(config) {
  max_rate_rad_per_s_ = config_.max_angular_speed_deg_per_s * kRadPerDeg;
  priors_.assign(static_cast<std::size_t>(model_.joint_count()), Prior{});
}

void ChainSolver::reset() noexcept {
  for (Prior& p : priors_) p.valid = false;
}

double ChainSolver::point_sigma_sq(int p, const MeasuredPoint& pt) const noexcept {
  double partial = config_.partial_sigma_mm;
  if (partial_sigma_mm_ != nullptr && p >= 0 && p < partial_sigma_count_)
    partial = partial_sigma_mm_[p];
  const double s = pt.partial ? std::max(partial, config_.point_sigma_mm) : config_.point_sigma_mm;
  return s * s;
}

double ChainSolver::sigma_sq(int p, const MeasuredPoint& pt) const noexcept {
  return point_sigma_sq(p, pt) + config_.model_sigma_mm * config_.model_sigma_mm;
}

void ChainSolver::forward(const BodyPoses& poses, ChainResult& out) const noexcept {
  for (const int j : model_.order()) {
    if (!active_[static_cast<std::size_t>(j)]) continue;
    const ChainJoint& cj = model_.joint(j);
    const auto up = static_cast<std::size_t>(cj.parent);
    const Iso3& T_wp = out.chain_body[up] ? out.T_world_body[up] : poses.bodies[up].T_world_body;
    out.T_world_body[static_cast<std::size_t>(cj.child)] =
        T_wp * model_.parent_child(j, R_rel_[static_cast<std::size_t>(j)]);
  }
}

bool ChainSolver::gauss_newton(const MeasuredPoint* pts, const BodyPoses& poses,
                               ChainResult& out) noexcept {
  int ndof = 0;
  for (const int j : model_.order()) {
    if (!active_[static_cast<std::size_t>(j)]) continue;
    dof_offset_[static_cast<std::size_t>(j)] = ndof;
    ndof += model_.joint(j).dof;
  }
  dof_ = 0;
  chi2_ = 0.0;
  residual_markers_ = 0;
  if (ndof == 0) return true;
  // The preallocated workspace (chain_solver.h): resizing within kMaxChainDof allocates
  // nothing, and only the ndof x ndof block is touched.
  chain_detail::NormalEquations& ne = *normal_;
  chain_detail::DofMatrix& H = ne.H;
  VecX& g = ne.g;
  Eigen::LDLT<chain_detail::DofMatrix>& ldlt = ne.ldlt;
  H.resize(ndof, ndof);
  g.resize(ndof);
  struct Block {
    int offset, dof;
    Mat3 B;
  };
  std::array<Block, kMaxBodies> path{};
  for (int iter = 0; iter < 8; ++iter) {
    forward(poses, out);
    H.setZero();
    g.setZero();
    double chi2 = 0.0;
    int count = 0;
    for (int b = 0; b < model_.body_count(); ++b) {
      const auto ub = static_cast<std::size_t>(b);
      if (!out.chain_body[ub]) continue;
      const std::vector<Vec3>& markers = model_.markers(b);
      // The chain from b up to its anchor: one Jacobian block per joint.
      int depth = 0;
      for (int jj = model_.joint_into(b); jj >= 0 && active_[static_cast<std::size_t>(jj)];
           jj = model_.joint_into(model_.joint(jj).parent)) {
        path[static_cast<std::size_t>(depth++)] =
            Block{dof_offset_[static_cast<std::size_t>(jj)], model_.joint(jj).dof, Mat3::Zero()};
      }
      for (std::size_t m = 0; m < markers.size(); ++m) {
        const int p = out.point_index_of_marker[ub][m];
        if (p < 0) continue;
        const Vec3 X = out.T_world_body[ub] * markers[m];
        const Vec3 r = X - pts[p].X_world;
        const double w = 1.0 / sigma_sq(p, pts[p]);
        chi2 += w * r.squaredNorm();
        ++count;
        int k = 0;
        for (int jj = model_.joint_into(b); jj >= 0 && active_[static_cast<std::size_t>(jj)];
             jj = model_.joint_into(model_.joint(jj).parent), ++k) {
          const ChainJoint& cj = model_.joint(jj);
          const auto up = static_cast<std::size_t>(cj.parent);
          const Iso3& T_wp =
              out.chain_body[up] ? out.T_world_body[up] : poses.bodies[up].T_world_body;
          const Vec3 d = X - T_wp * cj.c_parent;
          Block& blk = path[static_cast<std::size_t>(k)];
          if (cj.dof == 3)
            blk.B = -skew(d) * T_wp.linear();
          else
            blk.B.col(0) = (T_wp.linear() * cj.axis_parent).cross(d);
        }
        for (int a = 0; a < depth; ++a) {
          const Block& ba = path[static_cast<std::size_t>(a)];
          g.segment(ba.offset, ba.dof) += w * ba.B.leftCols(ba.dof).transpose() * r;
          for (int c = 0; c < depth; ++c) {
            const Block& bc = path[static_cast<std::size_t>(c)];
            H.block(ba.offset, bc.offset, ba.dof, bc.dof) +=
                w * ba.B.leftCols(ba.dof).transpose() * bc.B.leftCols(bc.dof);
          }
        }
      }
    }
    chi2_ = chi2;
    residual_markers_ = count;
    ldlt.compute(H);
    if (ldlt.info() != Eigen::Success) return false;
    const auto D = ldlt.vectorD();
    if (!(D.minCoeff() > 1e-12 * std::max(1.0, D.maxCoeff()))) return false;  // unobservable
    const VecX step = ldlt.solve(-g);
    if (!step.allFinite()) return false;
    for (const int j : model_.order()) {
      const auto uj = static_cast<std::size_t>(j);
      if (!active_[uj]) continue;
      const ChainJoint& cj = model_.joint(j);
      if (cj.dof == 3)
        R_rel_[uj] = exp_so3(step.segment<3>(dof_offset_[uj])) * R_rel_[uj];
      else
        R_rel_[uj] = Eigen::AngleAxisd(step[dof_offset_[uj]], cj.axis_parent).toRotationMatrix() *
                     R_rel_[uj];
    }
    if (step.cwiseAbs().maxCoeff() < 1e-10) break;
  }
  forward(poses, out);
  // Final residual and the covariance of the increments (inverse of the last H).
  chi2_ = 0.0;
  for (int b = 0; b < model_.body_count(); ++b) {
    const auto ub = static_cast<std::size_t>(b);
    if (!out.chain_body[ub]) continue;
    const std::vector<Vec3>& markers = model_.markers(b);
    for (std::size_t m = 0; m < markers.size(); ++m) {
      const int p = out.point_index_of_marker[ub][m];
      if (p >= 0)
        chi2_ += (out.T_world_body[ub] * markers[m] - pts[p].X_world).squaredNorm() /
                 sigma_sq(p, pts[p]);
    }
  }
  dof_ = 3 * residual_markers_ - ndof;
  // The diagonal blocks of H^-1, one column per degree of freedom: vector solves, so no
  // ndof^2 temporary and no blocked matrix solve (whose fixed-capacity scratch would be
  // ~147 KiB of stack at kMaxChainDof = 96).
  for (const int j : model_.order()) {
    const auto uj = static_cast<std::size_t>(j);
    if (!active_[uj]) continue;
    const int o = dof_offset_[uj];
    const int d = model_.joint(j).dof;
    for (int k = 0; k < d; ++k) {
      const VecX col = ldlt.solve(VecX::Unit(ndof, o + k));
      if (d == 3)
        cov_[uj].col(k) = col.segment<3>(o);
      else
        sd_dof_[static_cast<std::size_t>(o)] = std::sqrt(std::max(0.0, col[o]));
    }
  }
  return true;
}

}  // namespace mocap
