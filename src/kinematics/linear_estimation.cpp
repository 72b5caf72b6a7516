// Design: see linear_estimation.h. One SVD of the column-equilibrated measurement matrix
// serves the solution (ball: full-rank least squares; hinge: rank-5 pseudo-inverse) and
// the degeneracy diagnostics. Set-up code: allocates, returns Expected.
#include "kinematics/linear_estimation.h"

#include <Eigen/SVD>
#include <cmath>
#include <cstdio>
#include <numbers>

#include "core/units.h"

namespace mocap::kinematics {
namespace {

std::string g3(double a) {
  char buf[64];
  std::snprintf(buf, sizeof(buf), "%.3g", a);
  return buf;
}

std::string g4(double a) {
  char buf[64];
  std::snprintf(buf, sizeof(buf), "%.4g", a);
  return buf;
}

struct Svd6 {
  Eigen::MatrixXd U;                  // 3N x 6
  Eigen::Matrix<double, 6, 1> sigma;  // of the scaled matrix (= s_k)
  Eigen::Matrix<double, 6, 6> V;
};

// A (3N x 6) with rhs b; A is scaled by 1/sqrt(N) in place of per-column norms, which are
// all exactly sqrt(N) for [I -R_i] blocks (unit columns of I and of R_i).
Svd6 decompose(const Eigen::MatrixXd& A) {
  const double scale = 1.0 / std::sqrt(static_cast<double>(A.rows() / 3));
  Eigen::JacobiSVD<Eigen::MatrixXd> svd(A * scale, Eigen::ComputeThinU | Eigen::ComputeThinV);
  return Svd6{svd.matrixU(), svd.singularValues(), svd.matrixV()};
}

// x = D * V_k diag(1/sigma) U_k^T b with D = scale * I, using the first `rank` components.
Eigen::Matrix<double, 6, 1> solve(const Svd6& s, const Eigen::VectorXd& b, int rank) {
  const double scale = 1.0 / std::sqrt(static_cast<double>(b.size() / 3));
  Eigen::Matrix<double, 6, 1> x = Eigen::Matrix<double, 6, 1>::Zero();
  for (int k = 0; k < rank; ++k) {
    x += s.V.col(k) * (s.U.col(k).dot(b) / s.sigma[k]);
  }
  return x * scale;
}

bool finite_pose(const RelativePose& p) {
  return p.R_parent_child.allFinite() && p.t_parent_child.allFinite();
}

LinearDiagnostics diagnose(const Svd6& s, const Eigen::MatrixXd& A, const Eigen::VectorXd& b,
                           const Eigen::Matrix<double, 6, 1>& x) {
  LinearDiagnostics d;
  d.poses = static_cast<int>(A.rows() / 3);
  for (int k = 0; k < 6; ++k) d.singular_values[static_cast<std::size_t>(k)] = s.sigma[k];
  d.residual_rms_mm = (A * x - b).norm() / std::sqrt(static_cast<double>(d.poses));
  return d;
}

template <class Fill>
void build(int n, Eigen::MatrixXd& A, Eigen::VectorXd& b, Fill fill) {
  A.resize(3 * n, 6);
  b.resize(3 * n);
  for (int i = 0; i < n; ++i) fill(i, A.block<3, 6>(3 * i, 0), b.segment<3>(3 * i));
}

Expected<BallEstimate> ball_from_system(const Eigen::MatrixXd& A, const Eigen::VectorXd& b,
                                        const LinearOptions& options, const std::string& label) {
  const Svd6 s = decompose(A);
  const Eigen::Matrix<double, 6, 1> x = solve(s, b, 6);
  BallEstimate out;
  out.diagnostics = diagnose(s, A, b, x);
  const LinearDiagnostics& d = out.diagnostics;
  const double s5 = d.singular_value_deg(4), s6 = d.singular_value_deg(5);
  if (s6 < options.min_motion_deg) {
    if (s5 < options.min_motion_deg) {
      return Error{label + ": range of motion too small: rms rotation s5 = " + g3(s5) +
                   " deg, s6 = " + g3(s6) + " deg < " + g3(options.min_motion_deg) + " deg (" +
                   d.describe() + ")"};
    }
    return Error{label + ": moved about one axis only (hinge-like motion): s6 = " + g3(s6) +
                 " deg < " + g3(options.min_motion_deg) + " deg while s5 = " + g3(s5) + " deg (" +
                 d.describe() +
                 "); record rotation about a second axis, or declare the joint a hinge"};
  }
  out.center_parent = x.head<3>();
  out.center_child = x.tail<3>();
  return out;
}

std::string check_count(int n, const LinearOptions& options, const std::string& label) {
  if (n < options.min_poses) {
    return label + ": " + std::to_string(n) + " poses, at least " +
           std::to_string(options.min_poses) + " distinct poses needed";
  }
  return {};
}

}  // namespace

double LinearDiagnostics::singular_value_deg(int k) const noexcept {
  return singular_values[static_cast<std::size_t>(k)] * kDegPerRad;
}

std::string LinearDiagnostics::describe() const {
  std::string s = std::to_string(poses) + " poses, normalised singular values [";
  for (std::size_t k = 0; k < 6; ++k) s += (k ? " " : "") + g4(singular_values[k]);
  s += "], s4..s6 = " + g3(singular_value_deg(3)) + "/" + g3(singular_value_deg(4)) + "/" +
       g3(singular_value_deg(5)) + " deg";
  return s;
}

RelativePose relative_pose(const Iso3& T_world_parent, const Iso3& T_world_child) noexcept {
  const Mat3 Rt = T_world_parent.linear().transpose();
  return RelativePose{Rt * T_world_child.linear(),
                      Rt * (T_world_child.translation() - T_world_parent.translation())};
}

// The paper's Eq. 2 system [I  -R_i] [c_p; c_c] = t_i over the relative poses; an
// empty string on success, else the one-line error.
static std::string build_eq2(const std::vector<RelativePose>& poses, const LinearOptions& options,
                             const std::string& label, Eigen::MatrixXd& A, Eigen::VectorXd& b) {
  const int n = static_cast<int>(poses.size());
  if (auto e = check_count(n, options, label); !e.empty()) return e;
  for (const auto& p : poses) {
    if (!finite_pose(p)) return label + ": non-finite relative pose";
  }
  build(n, A, b, [&](int i, auto block, auto rhs) {
    const auto& p = poses[static_cast<std::size_t>(i)];
    block.template leftCols<3>().setIdentity();
    block.template rightCols<3>() = -p.R_parent_child;
    rhs = p.t_parent_child;
  });
  return {};
}

Expected<BallEstimate> estimate_ball(const std::vector<RelativePose>& poses,
                                     const LinearOptions& options, const std::string& label) {
  Eigen::MatrixXd A;
  Eigen::VectorXd b;
  if (auto e = build_eq2(poses, options, label, A, b); !e.empty()) return Error{e};
  return ball_from_system(A, b, options, label);
}

Expected<BallEstimate> estimate_ball_world(const std::vector<Iso3>& T_world_parent,
                                           const std::vector<Iso3>& T_world_child,
                                           const LinearOptions& options, const std::string& label) {
  if (T_world_parent.size() != T_world_child.size()) {
    return Error{label + ": parent and child pose lists differ in length"};
  }
  const int n = static_cast<int>(T_world_parent.size());
  if (auto e = check_count(n, options, label); !e.empty()) return Error{e};
  Eigen::MatrixXd A;
  Eigen::VectorXd b;
  build(n, A, b, [&](int i, auto block, auto rhs) {
    const auto& Tp = T_world_parent[static_cast<std::size_t>(i)];
    const auto& Tc = T_world_child[static_cast<std::size_t>(i)];
    block.template leftCols<3>() = Tp.linear();
    block.template rightCols<3>() = -Tc.linear();
    rhs = Tc.translation() - Tp.translation();
  });
  if (!A.allFinite() || !b.allFinite()) return Error{label + ": non-finite pose"};
  return ball_from_system(A, b, options, label);
}

Expected<HingeEstimate> estimate_hinge(const std::vector<RelativePose>& poses,
                                       const LinearOptions& options, const std::string& label,
                                       const Vec3& sign_hint_parent) {
  Eigen::MatrixXd A;
  Eigen::VectorXd b;
  if (auto e = build_eq2(poses, options, label, A, b); !e.empty()) return Error{e};
  const Svd6 s = decompose(A);
  const Eigen::Matrix<double, 6, 1> x = solve(s, b, 5);
  HingeEstimate out;
  out.diagnostics = diagnose(s, A, b, x);
  const LinearDiagnostics& d = out.diagnostics;
  const double s5 = d.singular_value_deg(4), s6 = d.singular_value_deg(5);
  if (s5 < options.min_motion_deg) {
    return Error{label + ": range of motion about the axis too small: s5 = " + g3(s5) + " deg < " +
                 g3(options.min_motion_deg) + " deg (" + d.describe() + ")"};
  }
  const double ratio = s6 / s5;
  if (ratio > options.max_hinge_off_axis_ratio) {
    return Error{label + ": not a hinge motion: s6/s5 = " + g3(ratio) + " > " +
                 g3(options.max_hinge_off_axis_ratio) + " (" + d.describe() +
                 "): rotation about more than one axis; declare the joint a ball joint"};
  }
  Vec3 a1 = s.V.col(5).head<3>();
  Vec3 a2 = s.V.col(5).tail<3>();
  if (a1.norm() < 1e-6 || a2.norm() < 1e-6) {
    return Error{label + ": null vector of M_5 has a zero 3-part (" + d.describe() + ")"};
  }
  a1.normalize();
  a2.normalize();
  if (a1.dot(sign_hint_parent) < 0.0) {
    a1 = -a1;
    a2 = -a2;
  }
  out.axis_parent = a1;
  out.axis_child = a2;
  out.center_parent = x.head<3>();
  out.center_child = x.tail<3>();
  return out;
}

}  // namespace mocap::kinematics
