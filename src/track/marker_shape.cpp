// Design: see marker_shape.h. Notation: for a symmetric 2x2 matrix Sigma, its trace
// t = Sxx + Syy and its traceless part as a 2-vector D = ((Sxx - Syy) / 2, Sxy);
// |D| = (l1 - l2) / 2 (half the eigenvalue gap), so |D| / (t / 2) is the anisotropy.
#include "track/marker_shape.h"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>

namespace mocap {
namespace {

constexpr double kPi = 3.14159265358979323846;

Vec2 traceless(const Eigen::Matrix2d& S) noexcept {
  return Vec2(0.5 * (S(0, 0) - S(1, 1)), S(0, 1));
}

// Pixel Jacobian of the camera model at normalised undistorted xn.
Eigen::Matrix2d pixel_jacobian(const CameraModel& cam, const Vec2& xn) noexcept {
  Eigen::Matrix2d K = Eigen::Matrix2d::Zero();
  K(0, 0) = cam.fx;
  K(1, 1) = cam.fy;
  return K * distort_jacobian(cam, xn);
}

}  // namespace

Eigen::Matrix2d blob_covariance_px(const detect::Blob& blob) noexcept {
  const double major = static_cast<double>(blob.major_axis_px);
  const double minor = static_cast<double>(blob.minor_axis_px);
  const double l1 = 0.25 * major * major;
  const double l2 = 0.25 * minor * minor;
  const double c = std::cos(static_cast<double>(blob.orientation_rad));
  const double s = std::sin(static_cast<double>(blob.orientation_rad));
  Eigen::Matrix2d S;
  S(0, 0) = l1 * c * c + l2 * s * s;
  S(1, 1) = l1 * s * s + l2 * c * c;
  S(0, 1) = S(1, 0) = (l1 - l2) * c * s;
  return S;
}

Expected<MarkerShapeModel> MarkerShapeModel::create(const CameraModel& cam,
                                                    double marker_diameter_mm,
                                                    const MarkerShapeConfig& config) {
  if (!(std::isfinite(marker_diameter_mm) && marker_diameter_mm > 0.0))
    return make_error("targets", "marker_diameter", "must be a positive number of mm");
  if (!(cam.fx > 0.0 && cam.fy > 0.0))
    return make_error("rig", cam.name, "focal length must be positive");
  const double p = config.false_partial_probability;
  if (!(std::isfinite(p) && p > 0.0 && p < 1.0))
    return make_error("tracker", "false_partial_probability", "must be in (0, 1)");
  MarkerShapeModel m;
  m.cam_ = cam;
  m.radius_mm_ = 0.5 * marker_diameter_mm;
  m.z_ = std::sqrt(-2.0 * std::log(p));
  m.config_ = config;
  return m;
}

bool MarkerShapeModel::silhouette(const Vec3& X_world, Eigen::Matrix2d& S, Vec2& x0,
                                  double& dist_mm) const noexcept {
  const Vec3 C = to_camera(cam_, X_world);
  dist_mm = C.norm();
  if (!(C.z() > radius_mm_) || !(dist_mm > radius_mm_)) return false;
  // Cone of the silhouette: x^T Q x = 0 with Q = c c^T - cos^2(alpha) I, x = (u, v, 1).
  const Vec3 c = C / dist_mm;
  const double sin_a = radius_mm_ / dist_mm;
  const double cos2 = 1.0 - sin_a * sin_a;
  const Eigen::Matrix2d A =
      c.head<2>() * c.head<2>().transpose() - cos2 * Eigen::Matrix2d::Identity();
  const Vec2 b = c.z() * c.head<2>();
  const double q33 = c.z() * c.z() - cos2;
  // A is negative definite while the whole cone stays in front of the camera.
  if (!(A.determinant() > 0.0 && A.trace() < 0.0)) return false;
  const Eigen::Matrix2d A_inv = A.inverse();
  x0 = -A_inv * b;
  const double kappa = b.dot(A_inv * b) - q33;  // (x - x0)^T A (x - x0) = kappa on the rim
  if (!(kappa < 0.0)) return false;
  S = kappa * A_inv;  // ellipse {(x - x0)^T S^-1 (x - x0) <= 1}, normalised units
  return std::isfinite(S.sum()) && std::isfinite(x0.sum());
}

bool MarkerShapeModel::predict(const Vec3& X_world, Eigen::Matrix2d& Sigma_px,
                               Vec2& center_px) const noexcept {
  Eigen::Matrix2d S;
  Vec2 x0;
  double dist = 0.0;
  if (!silhouette(X_world, S, x0, dist)) return false;
  const Eigen::Matrix2d J = pixel_jacobian(cam_, x0);
  Sigma_px = 0.25 * J * S * J.transpose();  // covariance of the filled ellipse
  center_px = normalized_to_pixel(cam_, x0);
  return std::isfinite(Sigma_px.sum()) && std::isfinite(center_px.sum());
}

double MarkerShapeModel::linearisation_error(const Eigen::Matrix2d& S,
                                             const Vec2& x0) const noexcept {
  const Eigen::Matrix2d J0 = pixel_jacobian(cam_, x0);
  const double j0 = J0.norm();
  if (!(j0 > 0.0)) return 0.0;
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> es(S);
  double lin = 0.0;
  for (int a = 0; a < 2; ++a) {
    // The silhouette's semi-axes (normalised units).
    const Vec2 d = std::sqrt(std::max(es.eigenvalues()(a), 0.0)) * es.eigenvectors().col(a);
    for (double sgn : {-1.0, 1.0}) {
      const double e = (pixel_jacobian(cam_, x0 + sgn * d) - J0).norm() / j0;
      lin = std::max(lin, e * e);
    }
  }
  return lin;
}

ShapeCheck MarkerShapeModel::check(const detect::Blob& blob, const Vec3& X_world,
                                   const ImageNoise& noise) const noexcept {
  ShapeCheck r;
  constexpr std::uint32_t kSuspect = detect::kBlobTouchesBorder | detect::kBlobMerged |
                                     detect::kBlobSplit | detect::kBlobTruncated;
  if ((blob.flags & kSuspect) != 0U) return r;  // cut off or shared: never whole
  r.whole = true;
  if (!config_.enabled) return r;
  Eigen::Matrix2d S;
  Vec2 x0;
  double dist = 0.0;
  if (!silhouette(X_world, S, x0, dist)) return r;  // no prediction: the flags decide
  const Eigen::Matrix2d J = pixel_jacobian(cam_, x0);
  const Eigen::Matrix2d Sg = 0.25 * J * S * J.transpose();
  const Eigen::Matrix2d Sm = blob_covariance_px(blob);
  const double t_m = Sm.trace();
  const double t_g = Sg.trace();
  const double W = static_cast<double>(blob.sum_dn);
  const double area = static_cast<double>(blob.area_px);
  if (!(t_m > 0.0 && t_g > 0.0 && W > 0.0 && area > 0.0)) return r;

  // Profile-free comparison of the anisotropy: D_m = k D_g, 0 <= k <= t_m / t_g.
  const Vec2 Dm = traceless(Sm);
  const Vec2 Dg = traceless(Sg);
  const double dg2 = Dg.squaredNorm();
  const double k = dg2 > 0.0 ? std::clamp(Dm.dot(Dg) / dg2, 0.0, t_m / t_g) : 0.0;
  const double n = 0.5 * t_m;
  r.residual = (Dm - k * Dg).norm() / n;

  // Tolerance (docs/detection.md): each traceless component of the measured moments
  // has a standard deviation from
  //  - the threshold cut: the ~2 pi R edge pixels lose a weight in [0, f) DN,
  //    f = threshold - background, i.e. sd f / sqrt(12) each, lever R^2 cos(2 phi) / 2;
  //  - the pixel noise (sigma_n, plus 1/12 DN^2 of rounding) on all N pixels.
  // R is the radius of the thresholded area. The residual is then Rayleigh-like:
  // tolerance = z * sigma + the linearisation error of the lens over the blob.
  const double R = std::sqrt(area / kPi);
  const double f = std::max(noise.threshold_dn - noise.background_dn, 1.0);
  const double R4 = R * R * R * R;
  const double var_cut = 2.0 * kPi * R * (f * f / 12.0) * R4 / 8.0;
  const double sn2 = noise.noise_dn * noise.noise_dn + 1.0 / 12.0;
  const double var_noise = area * sn2 * R4 / 24.0;
  const double sigma = std::sqrt(var_cut + var_noise) / (W * n);
  // Perspective: the brightness pattern is symmetric about the ball's axis, which the
  // projection keeps up to (rho / |C|)^2.
  const double persp = radius_mm_ / dist;
  r.tolerance = z_ * sigma + persp * persp;
  // Lens linearisation (only computed when it could matter): the moments of the truly
  // curved image deviate from the Jacobian's by the square of the relative change of J
  // across the silhouette.
  if (r.residual > r.tolerance) r.tolerance += linearisation_error(S, x0);
  r.whole = r.residual <= r.tolerance;
  return r;
}

double MarkerShapeModel::visible_fraction(const detect::Blob& blob,
                                          const Vec3& X_world) const noexcept {
  constexpr std::uint32_t kSuspect = detect::kBlobTouchesBorder | detect::kBlobMerged |
                                     detect::kBlobSplit | detect::kBlobTruncated;
  if ((blob.flags & kSuspect) != 0U) return 0.0;
  Eigen::Matrix2d Sigma;
  Vec2 centre;
  if (!predict(X_world, Sigma, centre)) return 0.0;
  const double det = Sigma.determinant();
  if (!(det > 0.0)) return 0.0;
  // A filled ellipse with semi-axes a, b has covariance eigenvalues a^2/4, b^2/4.
  const double area_pred = 4.0 * kPi * std::sqrt(det);
  // An area above the silhouette's is light from something else (a neighbouring ball,
  // a reflection) merged in: the same relative mass misplaced as a hidden part, f = 1/r.
  const double r = static_cast<double>(blob.area_px) / area_pred;
  if (!(r > 0.0)) return 0.0;
  return std::clamp(std::min(r, 1.0 / r), 0.0, 1.0);
}

double partial_centroid_shift(double f) noexcept {
  if (!(f > 0.0)) return 1.0;
  if (f >= 1.0) return 0.0;
  // f(d) = 1 - A_s(d) / pi increases monotonically from 0 (d = -1) to 1 (d = 1).
  const auto segment = [](double d) { return std::acos(d) - d * std::sqrt(1.0 - d * d); };
  double lo = -1.0, hi = 1.0;
  for (int i = 0; i < 60; ++i) {
    const double mid = 0.5 * (lo + hi);
    if (1.0 - segment(mid) / kPi < f)
      lo = mid;
    else
      hi = mid;
  }
  const double d = 0.5 * (lo + hi);
  const double kept = kPi - segment(d);
  const double c = 1.0 - d * d;
  return kept > 0.0 ? std::min(1.0, 2.0 * c * std::sqrt(c) / (3.0 * kept)) : 1.0;
}

}  // namespace mocap
