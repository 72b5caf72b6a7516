// Design: see rigid_fit.h.
#include "identify/rigid_fit.h"

#include <Eigen/Geometry>
#include <Eigen/SVD>
#include <cmath>

namespace mocap {

namespace {

void add_residuals(const FitPoints& src, const FitPoints& dst, int m, RigidFit& fit) noexcept {
  for (Eigen::Index i = 0; i < m; ++i) {
    const double r2 = (fit.T_dst_src * Vec3(src.col(i)) - Vec3(dst.col(i))).squaredNorm();
    fit.sum_sq_mm2 += r2;
    fit.max_sq_mm2 = r2 > fit.max_sq_mm2 ? r2 : fit.max_sq_mm2;
  }
}

// det(A) and, when adj is given, the adjugate of a 4x4 matrix (2x2 minors of the row
// pairs (0, 1) and (2, 3)): A * adj(A) = det(A) I.
double det_adj4(const Eigen::Matrix4d& A, Eigen::Matrix4d* adj) noexcept {
  const double s0 = A(0, 0) * A(1, 1) - A(1, 0) * A(0, 1);
  const double s1 = A(0, 0) * A(1, 2) - A(1, 0) * A(0, 2);
  const double s2 = A(0, 0) * A(1, 3) - A(1, 0) * A(0, 3);
  const double s3 = A(0, 1) * A(1, 2) - A(1, 1) * A(0, 2);
  const double s4 = A(0, 1) * A(1, 3) - A(1, 1) * A(0, 3);
  const double s5 = A(0, 2) * A(1, 3) - A(1, 2) * A(0, 3);
  const double c5 = A(2, 2) * A(3, 3) - A(3, 2) * A(2, 3);
  const double c4 = A(2, 1) * A(3, 3) - A(3, 1) * A(2, 3);
  const double c3 = A(2, 1) * A(3, 2) - A(3, 1) * A(2, 2);
  const double c2 = A(2, 0) * A(3, 3) - A(3, 0) * A(2, 3);
  const double c1 = A(2, 0) * A(3, 2) - A(3, 0) * A(2, 2);
  const double c0 = A(2, 0) * A(3, 1) - A(3, 0) * A(2, 1);
  if (adj != nullptr) {
    Eigen::Matrix4d& B = *adj;
    B(0, 0) = A(1, 1) * c5 - A(1, 2) * c4 + A(1, 3) * c3;
    B(0, 1) = -A(0, 1) * c5 + A(0, 2) * c4 - A(0, 3) * c3;
    B(0, 2) = A(3, 1) * s5 - A(3, 2) * s4 + A(3, 3) * s3;
    B(0, 3) = -A(2, 1) * s5 + A(2, 2) * s4 - A(2, 3) * s3;
    B(1, 0) = -A(1, 0) * c5 + A(1, 2) * c2 - A(1, 3) * c1;
    B(1, 1) = A(0, 0) * c5 - A(0, 2) * c2 + A(0, 3) * c1;
    B(1, 2) = -A(3, 0) * s5 + A(3, 2) * s2 - A(3, 3) * s1;
    B(1, 3) = A(2, 0) * s5 - A(2, 2) * s2 + A(2, 3) * s1;
    B(2, 0) = A(1, 0) * c4 - A(1, 1) * c2 + A(1, 3) * c0;
    B(2, 1) = -A(0, 0) * c4 + A(0, 1) * c2 - A(0, 3) * c0;
    B(2, 2) = A(3, 0) * s4 - A(3, 1) * s2 + A(3, 3) * s0;
    B(2, 3) = -A(2, 0) * s4 + A(2, 1) * s2 - A(2, 3) * s0;
    B(3, 0) = -A(1, 0) * c3 + A(1, 1) * c1 - A(1, 2) * c0;
    B(3, 1) = A(0, 0) * c3 - A(0, 1) * c1 + A(0, 2) * c0;
    B(3, 2) = -A(3, 0) * s3 + A(3, 1) * s1 - A(3, 2) * s0;
    B(3, 3) = A(2, 0) * s3 - A(2, 1) * s1 + A(2, 2) * s0;
  }
  return s0 * c5 - s1 * c4 + s2 * c3 + s3 * c2 - s4 * c1 + s5 * c0;
}

// The unit quaternion (w, x, y, z) of the rotation that best maps the demeaned src onto
// the demeaned dst, from S = sum src_i dst_i^T and the two sums of squared norms (QCP).
// False when the optimum is nearly degenerate or the input is not finite.
bool horn_quaternion(const Mat3& S, double g_src, double g_dst, Eigen::Vector4d& q) noexcept {
  const double sxx = S(0, 0), sxy = S(0, 1), sxz = S(0, 2);
  const double syx = S(1, 0), syy = S(1, 1), syz = S(1, 2);
  const double szx = S(2, 0), szy = S(2, 1), szz = S(2, 2);
  Eigen::Matrix4d N;                                      // Horn's symmetric, traceless matrix
  N << sxx + syy + szz, syz - szy, szx - sxz, sxy - syx,  //
      syz - szy, sxx - syy - szz, sxy + syx, szx + sxz,   //
      szx - sxz, sxy + syx, -sxx + syy - szz, syz + szy,  //
      sxy - syx, szx + sxz, syz + szy, -sxx - syy + szz;
  // det(N - l I) = l^4 + c2 l^2 + c1 l + c0.
  const double c2 = -2.0 * S.squaredNorm();
  const double c1 = -8.0 * S.determinant();
  const double c0 = det_adj4(N, nullptr);
  // The largest eigenvalue is at most (g_src + g_dst) / 2; the quartic is convex to the
  // right of it, so Newton's method from there decreases monotonically onto it.
  const double scale = 0.5 * (g_src + g_dst);
  if (!(scale > 0.0) || !std::isfinite(scale + c0 + c1 + c2)) return false;
  // p is evaluated from terms of size ~scale^4: once it is within their rounding error
  // the root is reached (another step would divide rounding noise by a derivative that
  // vanishes at a double root, e.g. an exact fit of nearly collinear points, and jump).
  const double p_noise = 1e-13 * scale * scale * scale * scale;
  double l = scale;
  for (int it = 0; it < 60; ++it) {
    const double l2 = l * l;
    const double p = (l2 + c2) * l2 + c1 * l + c0;
    const double dp = (4.0 * l2 + 2.0 * c2) * l + c1;
    if (!(p > p_noise) || !(dp > 0.0)) break;
    const double next = l - p / dp;
    const bool done = !(std::abs(next - l) > 1e-15 * scale);
    l = next;
    if (done) break;
  }
  // Null vector of N - l I: the largest column of its adjugate.
  Eigen::Matrix4d adj;
  det_adj4(N - l * Eigen::Matrix4d::Identity(), &adj);
  int best = 0;
  double best2 = adj.col(0).squaredNorm();
  for (int j = 1; j < 4; ++j) {
    const double n2 = adj.col(j).squaredNorm();
    if (n2 > best2) {
      best2 = n2;
      best = j;
    }
  }
  // Far from degenerate: the column is at least 1e-4 scale^3 (then its error is ~1e-12).
  const double s3 = scale * scale * scale;
  if (!(best2 > 1e-8 * s3 * s3) || !std::isfinite(best2)) return false;
  q = adj.col(best) / std::sqrt(best2);
  // The column must be an eigenvector of N for l (a check against any numerical slip).
  return (N * q - l * q).norm() <= 1e-9 * scale;
}

}  // namespace

RigidFit fit_rigid_umeyama(const FitPoints& src, const FitPoints& dst, int m) noexcept {
  RigidFit fit;
  fit.T_dst_src.matrix() = Eigen::umeyama(src.leftCols(m), dst.leftCols(m), false);
  add_residuals(src, dst, m, fit);
  return fit;
}

RigidFit fit_rigid(const FitPoints& src, const FitPoints& dst, int m) noexcept {
  Vec3 src_mean = Vec3::Zero(), dst_mean = Vec3::Zero();
  for (Eigen::Index i = 0; i < m; ++i) {
    src_mean += src.col(i);
    dst_mean += dst.col(i);
  }
  const double inv_m = 1.0 / static_cast<double>(m);
  src_mean *= inv_m;
  dst_mean *= inv_m;
  Mat3 S = Mat3::Zero();  // sum (src - src_mean)(dst - dst_mean)^T
  double g_src = 0.0, g_dst = 0.0;
  for (Eigen::Index i = 0; i < m; ++i) {
    const Vec3 a = Vec3(src.col(i)) - src_mean;
    const Vec3 b = Vec3(dst.col(i)) - dst_mean;
    S.noalias() += a * b.transpose();
    g_src += a.squaredNorm();
    g_dst += b.squaredNorm();
  }
  Eigen::Vector4d q;
  if (!horn_quaternion(S, g_src, g_dst, q)) return fit_rigid_umeyama(src, dst, m);
  RigidFit fit;
  const Eigen::Quaterniond rot(q(0), q(1), q(2), q(3));
  fit.T_dst_src.linear() = rot.toRotationMatrix();
  fit.T_dst_src.translation() = dst_mean - fit.T_dst_src.linear() * src_mean;
  add_residuals(src, dst, m, fit);
  return fit;
}

RigidFit fit_rigid_weighted(const FitPoints& src, const FitPoints& dst, const FitWeights& w,
                            int m) noexcept {
  double w_sum = 0.0;
  Vec3 src_mean = Vec3::Zero(), dst_mean = Vec3::Zero();
  for (Eigen::Index i = 0; i < m; ++i) {
    const double wi = w[static_cast<std::size_t>(i)];
    w_sum += wi;
    src_mean += wi * src.col(i);
    dst_mean += wi * dst.col(i);
  }
  src_mean /= w_sum;
  dst_mean /= w_sum;
  Mat3 H = Mat3::Zero();  // sum w (dst - dst_mean)(src - src_mean)^T
  for (Eigen::Index i = 0; i < m; ++i) {
    H += w[static_cast<std::size_t>(i)] * (Vec3(dst.col(i)) - dst_mean) *
         (Vec3(src.col(i)) - src_mean).transpose();
  }
  const Eigen::JacobiSVD<Mat3> svd(H, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Mat3 D = Mat3::Identity();
  if ((svd.matrixU() * svd.matrixV().transpose()).determinant() < 0.0) D(2, 2) = -1.0;
  RigidFit fit;
  fit.T_dst_src.linear() = svd.matrixU() * D * svd.matrixV().transpose();
  fit.T_dst_src.translation() = dst_mean - fit.T_dst_src.linear() * src_mean;
  for (Eigen::Index i = 0; i < m; ++i) {
    const double r2 = w[static_cast<std::size_t>(i)] *
                      (fit.T_dst_src * Vec3(src.col(i)) - Vec3(dst.col(i))).squaredNorm();
    fit.sum_sq_mm2 += r2;
    fit.max_sq_mm2 = r2 > fit.max_sq_mm2 ? r2 : fit.max_sq_mm2;
  }
  return fit;
}

}  // namespace mocap
