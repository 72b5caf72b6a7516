// Design: see two_view.h. niter2 derivation in our own notation (constraint
// g(a, b) = b^T F a with a = [s0; 1], b = [s1; 1], corrections only in x and y):
//   g(a - S^T da, b - S^T db) = c - n_a.da - n_b.db + db^T E2 da,
//   n_a = (F^T b)_xy, n_b = (F a)_xy, c = b^T F a, E2 = F's top-left 2x2.
// The optimum has da, db parallel to the constraint gradients *at the corrected
// points*. Step 1 takes the gradients at the measured points, (da, db) = l (n_a, n_b),
// and solves the quadratic A l^2 - 2 B l + c = 0 (A = n_b^T E2 n_a,
// B = (|n_a|^2 + |n_b|^2) / 2) for its small root l = c / (B + sqrt(B^2 - A c)).
// Step 2 re-evaluates the gradients at the corrected points (n' = n - E2 d) and
// projects the step-1 correction onto them: l2 = l (n.n') / |n'|^2, with
// n.n' = 2 sqrt(B^2 - A c) exactly. In ordinary geometry this is the optimum to
// ~1e-9 px. Near the epipoles (points close to the baseline direction) the bilinear
// term matters more, so niter2 is followed by polish steps of the same fixed point
// (gradients at the current corrected points, exact quadratic for the step length, as
// in Lindstrom's niter1) until the correction moves by < 1e-10 px; normally one step
// confirms convergence. Verified against a brute-force pencil search in the tests.
#include "stereo/two_view.h"

#include <Eigen/SVD>
#include <cmath>

#include "core/mat3_product.h"

namespace mocap {
namespace {

Mat3 skew(const Vec3& v) {
  Mat3 S;
  S << 0.0, -v.z(), v.y(), v.z(), 0.0, -v.x(), -v.y(), v.x(), 0.0;
  return S;
}

}  // namespace

bool compute_stereo_geometry(const CameraModel& cam0, const CameraModel& cam1,
                             StereoGeometry& g) noexcept {
  if (!(cam0.fx > 0.0 && cam0.fy > 0.0 && cam1.fx > 0.0 && cam1.fy > 0.0)) return false;
  g.fx0 = cam0.fx;
  g.fy0 = cam0.fy;
  g.fx1 = cam1.fx;
  g.fy1 = cam1.fy;
  g.R_0w = cam0.R_cam_world;
  g.t_0w = cam0.t_cam_world;
  g.R_10 = cam1.R_cam_world * cam0.R_cam_world.transpose();
  g.t_10 = cam1.t_cam_world - g.R_10 * cam0.t_cam_world;
  g.baseline_mm = g.t_10.norm();
  if (!(g.baseline_mm > 1e-9) || !std::isfinite(g.baseline_mm)) return false;
  g.baseline_dir_0 = -(g.R_10.transpose() * g.t_10) / g.baseline_mm;
  const Vec3 d0_inv(1.0 / cam0.fx, 1.0 / cam0.fy, 1.0);
  const Vec3 d1_inv(1.0 / cam1.fx, 1.0 / cam1.fy, 1.0);
  const Mat3 E = skew(g.t_10 / g.baseline_mm) * g.R_10;
  Mat3 F = d1_inv.asDiagonal() * E * d0_inv.asDiagonal();
  g.F_s = F / F.norm();  // the method is invariant to the scale of F
  return true;
}

Expected<StereoGeometry> make_stereo_geometry(const CameraModel& cam0, const CameraModel& cam1) {
  StereoGeometry g;
  if (!(cam0.fx > 0.0 && cam0.fy > 0.0))
    return make_error("stereo", cam0.name, "focal length must be positive");
  if (!(cam1.fx > 0.0 && cam1.fy > 0.0))
    return make_error("stereo", cam1.name, "focal length must be positive");
  if (!compute_stereo_geometry(cam0, cam1, g))
    return make_error("stereo", cam0.name + "/" + cam1.name,
                      "zero baseline (the two optical centres coincide)");
  return g;
}

void epipolar_distances_px(const StereoGeometry& g, const Vec2& s0, const Vec2& s1, double& d0,
                           double& d1) noexcept {
  const Vec3 a(s0.x(), s0.y(), 1.0);
  const Vec3 b(s1.x(), s1.y(), 1.0);
  const Vec3 l1 = mul(g.F_s, a);             // line in image 1
  const Vec3 l0 = mul_transposed(g.F_s, b);  // line in image 0
  const double c = b.dot(l1);                // == a.dot(l0)
  const double n1 = l1.head<2>().norm();
  const double n0 = l0.head<2>().norm();
  d1 = n1 > 0.0 ? std::abs(c) / n1 : HUGE_VAL;
  d0 = n0 > 0.0 ? std::abs(c) / n0 : HUGE_VAL;
}

void niter2_correct(const Mat3& F, const Vec2& s0, const Vec2& s1, Vec2& s0c, Vec2& s1c,
                    int max_polish_iterations) noexcept {
  constexpr double kConvergedPx = 1e-10;
  const Vec3 a(s0.x(), s0.y(), 1.0);
  const Vec3 b(s1.x(), s1.y(), 1.0);
  const Vec3 Fa = mul(F, a);
  const Vec3 Ftb = mul_transposed(F, b);
  const Eigen::Matrix2d E2 = F.topLeftCorner<2, 2>();
  const Vec2 n_a = Ftb.head<2>();
  const Vec2 n_b = Fa.head<2>();
  const double c = b.dot(Fa);
  const double A = n_b.dot(E2 * n_a);
  const double B = 0.5 * (n_a.squaredNorm() + n_b.squaredNorm());
  const double d = std::sqrt(std::max(B * B - A * c, 0.0));
  const double denom = B + d;
  s0c = s0;
  s1c = s1;
  if (!(denom > 0.0)) return;  // both points at their epipoles: nothing to correct
  const double l1 = c / denom;
  const Vec2 da = l1 * n_a;
  const Vec2 db = l1 * n_b;
  const Vec2 n_a2 = n_a - E2.transpose() * db;
  const Vec2 n_b2 = n_b - E2 * da;
  const double nn = n_a2.squaredNorm() + n_b2.squaredNorm();
  if (!(nn > 0.0)) return;
  const double l2 = l1 * 2.0 * d / nn;
  Vec2 da_k = l2 * n_a2;
  Vec2 db_k = l2 * n_b2;
  // Polish (near-degenerate geometry only changes anything): the exact-constraint
  // step of the same fixed point, with the gradients at the current corrected points,
  // until the correction moves by less than kConvergedPx.
  for (int it = 0; it < max_polish_iterations; ++it) {
    const Vec2 m_a = n_a - E2.transpose() * db_k;
    const Vec2 m_b = n_b - E2 * da_k;
    const double Ak = m_b.dot(E2 * m_a);
    const double Bk = 0.5 * (n_a.dot(m_a) + n_b.dot(m_b));
    const double dk = std::sqrt(std::max(Bk * Bk - Ak * c, 0.0));
    const double den = Bk + dk;
    if (!(std::abs(den) > 0.0)) break;
    const double lk = c / den;
    const Vec2 da_n = lk * m_a;
    const Vec2 db_n = lk * m_b;
    const double moved2 = (da_n - da_k).squaredNorm() + (db_n - db_k).squaredNorm();
    da_k = da_n;
    db_k = db_n;
    if (moved2 < kConvergedPx * kConvergedPx) break;
  }
  s0c = s0 - da_k;
  s1c = s1 - db_k;
}

bool intersect_rays(const StereoGeometry& g, const Vec2& xn0c, const Vec2& xn1c,
                    Vec3& X_cam0) noexcept {
  const Vec3 x0(xn0c.x(), xn0c.y(), 1.0);
  const Vec3 x1(xn1c.x(), xn1c.y(), 1.0);
  const Vec3 d = mul(g.R_10, x0);  // ray 0 direction in camera-1 coordinates
  const Vec3 w = x1.cross(d);
  const double w2 = w.squaredNorm();
  if (!(w2 > 1e-24 * x1.squaredNorm() * d.squaredNorm())) return false;
  // x1 x (z d + t) = 0  =>  z w = -(x1 x t), solved in the least-squares sense.
  const double z = -w.dot(x1.cross(g.t_10)) / w2;
  if (!std::isfinite(z)) return false;
  X_cam0 = z * x0;
  return true;
}

bool triangulate_niter2(const StereoGeometry& g, const Vec2& xn0, const Vec2& xn1,
                        Vec3& X_world) noexcept {
  const Vec2 s0(g.fx0 * xn0.x(), g.fy0 * xn0.y());
  const Vec2 s1(g.fx1 * xn1.x(), g.fy1 * xn1.y());
  Vec2 s0c, s1c;
  niter2_correct(g.F_s, s0, s1, s0c, s1c);
  Vec3 X0;
  if (!intersect_rays(g, Vec2(s0c.x() / g.fx0, s0c.y() / g.fy0),
                      Vec2(s1c.x() / g.fx1, s1c.y() / g.fy1), X0))
    return false;
  if (!(X0.z() > 0.0) || !((g.R_10 * X0 + g.t_10).z() > 0.0)) return false;
  X_world = g.R_0w.transpose() * (X0 - g.t_0w);
  return true;
}

bool triangulate_niter2(const CameraModel& c0, const CameraModel& c1, const Vec2& xn0,
                        const Vec2& xn1, Vec3& X_world) noexcept {
  StereoGeometry g;
  if (!compute_stereo_geometry(c0, c1, g)) return false;
  return triangulate_niter2(g, xn0, xn1, X_world);
}

bool triangulate_pixels(const StereoGeometry& g, const CameraModel& c0, const CameraModel& c1,
                        const Vec2& px0, const Vec2& px1, Vec3& X_world,
                        double& reproj_px) noexcept {
  Vec2 xn0, xn1;
  Vec3 X;
  double rms = 0.0;
  if (!undistort_pixel(c0, px0, xn0) || !undistort_pixel(c1, px1, xn1)) return false;
  if (!triangulate_niter2(g, xn0, xn1, X)) return false;
  if (!reprojection_rms_px(c0, c1, X, px0, px1, rms)) return false;
  X_world = X;
  reproj_px = rms;
  return true;
}

bool triangulate_dlt(const StereoGeometry& g, const Vec2& xn0, const Vec2& xn1,
                     Vec3& X_world) noexcept {
  // Camera-0 frame, lengths in baselines (keeps the 4x4 system well conditioned).
  Eigen::Matrix<double, 3, 4> P1;
  P1.leftCols<3>() = g.R_10;
  P1.col(3) = g.t_10 / g.baseline_mm;
  Eigen::Matrix4d A;
  A.row(0) << -1.0, 0.0, xn0.x(), 0.0;  // x P0.row(2) - P0.row(0), P0 = [I | 0]
  A.row(1) << 0.0, -1.0, xn0.y(), 0.0;
  A.row(2) = xn1.x() * P1.row(2) - P1.row(0);
  A.row(3) = xn1.y() * P1.row(2) - P1.row(1);
  const Eigen::JacobiSVD<Eigen::Matrix4d> svd(A, Eigen::ComputeFullV);
  const Eigen::Vector4d Xh = svd.matrixV().col(3);
  if (!(std::abs(Xh(3)) > 1e-15 * Xh.head<3>().norm())) return false;
  const Vec3 X0 = Xh.head<3>() / Xh(3) * g.baseline_mm;
  if (!(X0.z() > 0.0) || !((g.R_10 * X0 + g.t_10).z() > 0.0)) return false;
  X_world = g.R_0w.transpose() * (X0 - g.t_0w);
  return true;
}

bool reprojection_rms_px(const CameraModel& c0, const CameraModel& c1, const Vec3& X_world,
                         const Vec2& px0, const Vec2& px1, double& rms_px) noexcept {
  Vec2 p0, p1;
  if (!project(c0, X_world, p0) || !project(c1, X_world, p1)) return false;
  rms_px = std::sqrt(0.5 * ((p0 - px0).squaredNorm() + (p1 - px1).squaredNorm()));
  return true;
}

}  // namespace mocap
