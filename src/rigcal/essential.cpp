// Design: see essential.h.
#include "rigcal/essential.h"

#include <Eigen/SVD>
#include <algorithm>
#include <random>

namespace mocap::rigcal {
namespace {

// Isotropic normalisation: centroid to 0, mean distance sqrt(2).
Mat3 normaliser(std::span<const Vec2> x) {
  Vec2 c = Vec2::Zero();
  for (const Vec2& p : x) c += p;
  c /= static_cast<double>(x.size());
  double d = 0.0;
  for (const Vec2& p : x) d += (p - c).norm();
  d /= static_cast<double>(x.size());
  const double s = d > 1e-12 ? std::sqrt(2.0) / d : 1.0;
  Mat3 T;
  T << s, 0, -s * c.x(), 0, s, -s * c.y(), 0, 0, 1;
  return T;
}

}  // namespace

bool essential_8point(std::span<const Vec2> x0, std::span<const Vec2> x1, Mat3& E) {
  const std::size_t n = x0.size();
  if (n < 8 || x1.size() != n) return false;
  const Mat3 T0 = normaliser(x0), T1 = normaliser(x1);
  Eigen::MatrixXd A(static_cast<Eigen::Index>(n), 9);
  for (std::size_t i = 0; i < n; ++i) {
    const Vec3 a = T0 * x0[i].homogeneous();
    const Vec3 b = T1 * x1[i].homogeneous();
    // b^T E a = 0, E row-major.
    A.row(static_cast<Eigen::Index>(i)) << b.x() * a.x(), b.x() * a.y(), b.x(), b.y() * a.x(),
        b.y() * a.y(), b.y(), a.x(), a.y(), 1.0;
  }
  Eigen::JacobiSVD<Eigen::MatrixXd> svd(A, Eigen::ComputeFullV);
  const Eigen::VectorXd e = svd.matrixV().col(8);
  Mat3 En;
  En << e(0), e(1), e(2), e(3), e(4), e(5), e(6), e(7), e(8);
  Mat3 Ed = T1.transpose() * En * T0;
  Eigen::JacobiSVD<Mat3> s2(Ed, Eigen::ComputeFullU | Eigen::ComputeFullV);
  E = s2.matrixU() * Vec3(1, 1, 0).asDiagonal() * s2.matrixV().transpose();
  return E.allFinite() && s2.singularValues()(1) > 1e-12;
}

double sampson_distance(const Mat3& E, const Vec2& x0, const Vec2& x1) noexcept {
  const Vec3 a = x0.homogeneous(), b = x1.homogeneous();
  const Vec3 Ea = E * a, Etb = E.transpose() * b;
  const double num = b.dot(Ea);
  const double den = Ea.x() * Ea.x() + Ea.y() * Ea.y() + Etb.x() * Etb.x() + Etb.y() * Etb.y();
  return den > 0.0 ? std::fabs(num) / std::sqrt(den) : 1e9;
}

Vec3 triangulate_linear(const Mat3& R, const Vec3& t, const Vec2& x0, const Vec2& x1) {
  Eigen::Matrix4d A;
  A.row(0) << -1, 0, x0.x(), 0;
  A.row(1) << 0, -1, x0.y(), 0;
  const Eigen::Matrix<double, 3, 4> P1 = (Eigen::Matrix<double, 3, 4>() << R, t).finished();
  A.row(2) = x1.x() * P1.row(2) - P1.row(0);
  A.row(3) = x1.y() * P1.row(2) - P1.row(1);
  Eigen::JacobiSVD<Eigen::Matrix4d> svd(A, Eigen::ComputeFullV);
  const Eigen::Vector4d X = svd.matrixV().col(3);
  return X.head<3>() / X(3);
}

Expected<RelativePose> estimate_relative_pose(std::span<const Vec2> x0, std::span<const Vec2> x1,
                                              const EssentialOptions& opt) {
  const std::size_t n = x0.size();
  if (n < 8 || x1.size() != n)
    return make_error("essential", "",
                      "needs at least 8 correspondences, got " + std::to_string(n));
  std::mt19937_64 rng(opt.seed);
  std::uniform_int_distribution<std::size_t> pick(0, n - 1);
  std::vector<Vec2> s0(8), s1(8);
  Mat3 best_E = Mat3::Zero();
  int best_count = -1;
  for (int it = 0; it < opt.iterations; ++it) {
    std::array<std::size_t, 8> idx{};
    for (std::size_t k = 0; k < 8; ++k) {
      bool dup = true;
      while (dup) {
        idx[k] = pick(rng);
        dup = std::find(idx.begin(), idx.begin() + static_cast<std::ptrdiff_t>(k), idx[k]) !=
              idx.begin() + static_cast<std::ptrdiff_t>(k);
      }
      s0[k] = x0[idx[k]];
      s1[k] = x1[idx[k]];
    }
    Mat3 E;
    if (!essential_8point(s0, s1, E)) continue;
    int count = 0;
    for (std::size_t i = 0; i < n; ++i) count += sampson_distance(E, x0[i], x1[i]) < opt.threshold;
    if (count > best_count) {
      best_count = count;
      best_E = E;
    }
  }
  if (best_count < 8) return make_error("essential", "", "no consistent epipolar geometry");
  RelativePose out;
  // Refit on the consensus set twice (the set can grow with a better E).
  Mat3 E = best_E;
  for (int pass = 0; pass < 2; ++pass) {
    std::vector<Vec2> i0, i1;
    for (std::size_t i = 0; i < n; ++i) {
      if (sampson_distance(E, x0[i], x1[i]) < opt.threshold) {
        i0.push_back(x0[i]);
        i1.push_back(x1[i]);
      }
    }
    Mat3 E2;
    if (i0.size() >= 8 && essential_8point(i0, i1, E2)) E = E2;
  }
  out.E = E;
  out.inlier.assign(n, false);
  for (std::size_t i = 0; i < n; ++i) {
    out.inlier[i] = sampson_distance(E, x0[i], x1[i]) < opt.threshold;
    out.inlier_count += out.inlier[i] ? 1 : 0;
  }
  // Decompose: E = U diag(1,1,0) V^T; R = U W V^T or U W^T V^T; t = +-u3.
  Eigen::JacobiSVD<Mat3> svd(E, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Mat3 U = svd.matrixU(), V = svd.matrixV();
  if (U.determinant() < 0) U.col(2) *= -1.0;
  if (V.determinant() < 0) V.col(2) *= -1.0;
  Mat3 W;
  W << 0, -1, 0, 1, 0, 0, 0, 0, 1;
  const std::array<Mat3, 2> Rs = {U * W * V.transpose(), U * W.transpose() * V.transpose()};
  const std::array<Vec3, 2> ts = {Vec3(U.col(2)), Vec3(-U.col(2))};
  int best_front = -1;
  for (const Mat3& R : Rs) {
    for (const Vec3& t : ts) {
      int front = 0;
      for (std::size_t i = 0; i < n; ++i) {
        if (!out.inlier[i]) continue;
        const Vec3 X = triangulate_linear(R, t, x0[i], x1[i]);
        front += (X.z() > 0.0 && (R * X + t).z() > 0.0) ? 1 : 0;
      }
      if (front > best_front) {
        best_front = front;
        out.R_1_0 = R;
        out.t_1_0 = t.normalized();
      }
    }
  }
  if (best_front < out.inlier_count / 2)
    return make_error("essential", "",
                      "no pose puts the wand in front of both cameras (" +
                          std::to_string(best_front) + " of " + std::to_string(out.inlier_count) +
                          " points)");
  return out;
}

}  // namespace mocap::rigcal
