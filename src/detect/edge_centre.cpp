// Design: see edge_centre.h. The circle fit is Kasa's algebraic fit (a 3x3 linear
// system, Eigen's LU) for the start, then Gauss-Newton on the geometric distance over the inliers,
// with the inlier set re-chosen after each step from the current residuals.
#include "detect/edge_centre.h"

#include <Eigen/LU>
#include <algorithm>
#include <array>
#include <cmath>

#include "core/median.h"

namespace mocap::detect {
namespace {

double edge_pixel_dn(const ImageView& img, int x, int y) noexcept {
  return img.format == PixelFormat::kMono8 ? static_cast<double>(img.row8(y)[x])
                                           : static_cast<double>(img.row16(y)[x]);
}

// Bilinear sample at (x, y); false outside the image's interpolable area.
bool sample_bilinear(const ImageView& img, double x, double y, double& v) noexcept {
  if (!(x >= 0.0 && y >= 0.0 && x <= img.width - 1.0 && y <= img.height - 1.0)) return false;
  const int x0 = std::min(static_cast<int>(x), img.width - 2);
  const int y0 = std::min(static_cast<int>(y), img.height - 2);
  const double fx = x - x0, fy = y - y0;
  v = (1.0 - fy) * ((1.0 - fx) * edge_pixel_dn(img, x0, y0) + fx * edge_pixel_dn(img, x0 + 1, y0)) +
      fy * ((1.0 - fx) * edge_pixel_dn(img, x0, y0 + 1) + fx * edge_pixel_dn(img, x0 + 1, y0 + 1));
  return true;
}

struct EdgePoint {
  double x, y;   // unstretched frame, relative to the blob's centroid
  double sigma;  // edge position noise (px)
  int ray;       // index of the ray (angular order)
  bool inlier;
};

}  // namespace

EdgeCentre edge_centre(const ImageView& img, const Blob& blob, double noise_dn, double radial_x,
                       double radial_y, double radial_stretch, const EdgeCentreConfig& cfg,
                       EdgeAxis axis) noexcept {
  EdgeCentre out;
  const int rays = std::clamp(cfg.rays, 8, kMaxEdgeRays);
  const double bg = blob.background_dn, peak = blob.peak_dn;
  const double noise = std::max(noise_dn, 0.5);  // a quantisation floor for noiseless images
  if (img.empty() || !(peak - bg > cfg.min_contrast_sigmas * noise)) return out;
  if (!(radial_stretch > 0.2 && radial_stretch < 5.0)) radial_stretch = 1.0;
  const double rn = std::hypot(radial_x, radial_y);
  const double ux = rn > 0.0 ? radial_x / rn : 1.0, uy = rn > 0.0 ? radial_y / rn : 0.0;
  const double level = bg + cfg.level * (peak - bg);
  const double r_max = 0.5 * std::max(blob.x_max - blob.x_min, blob.y_max - blob.y_min) + 3.0;
  const double step = std::clamp(cfg.step_px, 0.05, 1.0);

  // An occluder axis: the rays within axis_half_angle_deg of it are not used.
  const double an = std::hypot(axis.x, axis.y);
  const double ax = an > 0.0 ? axis.x / an : 0.0, ay = an > 0.0 ? axis.y / an : 0.0;
  const double cos_half =
      an > 0.0 ? std::cos(std::clamp(cfg.axis_half_angle_deg, 0.0, 70.0) * M_PI / 180.0) : 2.0;
  std::array<EdgePoint, kMaxEdgeRays> pts{};
  int n = 0, used_rays = 0;
  for (int k = 0; k < rays; ++k) {
    const double a = 2.0 * M_PI * k / rays;
    const double dx = std::cos(a), dy = std::sin(a);
    if (std::fabs(dx * ax + dy * ay) > cos_half) continue;
    ++used_rays;
    double prev = 0.0;
    if (!sample_bilinear(img, blob.x_px, blob.y_px, prev) || prev < level) continue;
    for (double r = step; r <= r_max; r += step) {
      double v = 0.0;
      if (!sample_bilinear(img, blob.x_px + r * dx, blob.y_px + r * dy, v)) break;
      if (v < level) {
        const double t = (prev - level) / (prev - v);  // in (0, 1]
        const double re = r - step + t * step;
        const double grad = (prev - v) / step;  // DN per px, > 0
        const double ex = re * dx, ey = re * dy;
        // Unstretch: divide the radial component by the stretch.
        const double along = ex * ux + ey * uy;
        const double shrink = (1.0 / radial_stretch - 1.0) * along;
        pts[static_cast<std::size_t>(n++)] = {ex + shrink * ux, ey + shrink * uy,
                                              noise / std::max(grad, 1e-9), k, true};
        break;
      }
      prev = v;
    }
  }
  out.edge_points = n;
  const int min_inliers =
      std::max(6, static_cast<int>(std::ceil(cfg.min_inlier_fraction * used_rays)));
  if (n < min_inliers) return out;

  // Kasa's fit over all points: x^2 + y^2 + D x + E y + F = 0.
  Eigen::Matrix3d A = Eigen::Matrix3d::Zero();
  Eigen::Vector3d b = Eigen::Vector3d::Zero();
  for (int i = 0; i < n; ++i) {
    const EdgePoint& q = pts[static_cast<std::size_t>(i)];
    const Eigen::Vector3d row(q.x, q.y, 1.0);
    A += row * row.transpose();
    b -= row * (q.x * q.x + q.y * q.y);
  }
  const Eigen::FullPivLU<Eigen::Matrix3d> kasa(A);
  if (!kasa.isInvertible()) return out;
  const Eigen::Vector3d p = kasa.solve(b);
  double cx = -0.5 * p[0], cy = -0.5 * p[1];
  double rad2 = cx * cx + cy * cy - p[2];
  if (!(rad2 > 0.0)) return out;
  double rad = std::sqrt(rad2);

  std::array<double, kMaxEdgeRays> abs_res{};
  std::array<double, kMaxEdgeRays> sig{};
  int inl = 0;
  for (int iter = 0; iter < 8; ++iter) {
    // Robust scale: the median edge noise, or the points' own spread (MAD), the larger.
    for (int i = 0; i < n; ++i) {
      const EdgePoint& q = pts[static_cast<std::size_t>(i)];
      abs_res[static_cast<std::size_t>(i)] = std::fabs(std::hypot(q.x - cx, q.y - cy) - rad);
      sig[static_cast<std::size_t>(i)] = q.sigma;
    }
    const auto un = static_cast<std::size_t>(n);
    const double sigma_median = median_in_place(sig.data(), un);
    const double scale = std::max(1.4826 * median_in_place(abs_res.data(), un), sigma_median);
    // A hidden part darkens the edge beyond itself by the blur: the rays within one edge
    // width (contrast / gradient, the median over the rays) of a rejected ray's edge point
    // along the rim are rejected with it.
    const double edge_width_px = (peak - bg) * sigma_median / noise;
    const int spread =
        std::min(rays / 4, static_cast<int>(std::ceil(cfg.hidden_spread_widths * edge_width_px *
                                                      rays / (2.0 * M_PI * std::max(rad, 0.5)))));
    std::array<bool, kMaxEdgeRays> hidden{};
    for (int i = 0; i < n; ++i) {
      EdgePoint& q = pts[static_cast<std::size_t>(i)];
      const double e = std::hypot(q.x - cx, q.y - cy) - rad;
      q.inlier = std::fabs(e) <= cfg.inlier_sigmas * std::max(scale, q.sigma);
      if (!q.inlier) {
        for (int j = -spread; j <= spread; ++j)
          hidden[static_cast<std::size_t>((q.ray + j + rays) % rays)] = true;
      }
    }
    // Then the hidden arcs grow while the next ray's edge point still lies inside the
    // circle by more than one sigma (the blurred flank of the hidden part).
    for (bool grew = cfg.grow_hidden; grew;) {
      grew = false;
      for (int i = 0; i < n; ++i) {
        const EdgePoint& q = pts[static_cast<std::size_t>(i)];
        if (hidden[static_cast<std::size_t>(q.ray)]) continue;
        const bool beside = hidden[static_cast<std::size_t>((q.ray + 1) % rays)] ||
                            hidden[static_cast<std::size_t>((q.ray + rays - 1) % rays)];
        const double e = std::hypot(q.x - cx, q.y - cy) - rad;
        if (beside && e < -std::max(scale, q.sigma)) {
          hidden[static_cast<std::size_t>(q.ray)] = true;
          grew = true;
        }
      }
    }
    inl = 0;
    for (int i = 0; i < n; ++i) {
      EdgePoint& q = pts[static_cast<std::size_t>(i)];
      q.inlier = q.inlier && !hidden[static_cast<std::size_t>(q.ray)];
      inl += q.inlier ? 1 : 0;
    }
    if (inl < min_inliers) return out;
    // One Gauss-Newton step on the geometric residual |q - c| - rad.
    Eigen::Matrix3d H = Eigen::Matrix3d::Zero();
    Eigen::Vector3d g = Eigen::Vector3d::Zero();
    for (int i = 0; i < n; ++i) {
      const EdgePoint& q = pts[static_cast<std::size_t>(i)];
      if (!q.inlier) continue;
      const double dist = std::max(std::hypot(q.x - cx, q.y - cy), 1e-9);
      const Eigen::Vector3d J(-(q.x - cx) / dist, -(q.y - cy) / dist, -1.0);
      H += J * J.transpose();
      g -= J * (dist - rad);
    }
    const Eigen::FullPivLU<Eigen::Matrix3d> step_lu(H);
    if (!step_lu.isInvertible()) return out;
    const Eigen::Vector3d d = step_lu.solve(g);
    cx += d[0];
    cy += d[1];
    rad += d[2];
    if (!(rad > 0.0)) return out;
    if (std::fabs(d[0]) + std::fabs(d[1]) < 1e-6) break;
  }
  double ss = 0.0;
  for (int i = 0; i < n; ++i) {
    const EdgePoint& q = pts[static_cast<std::size_t>(i)];
    if (!q.inlier) continue;
    const double e = std::hypot(q.x - cx, q.y - cy) - rad;
    ss += e * e;
  }
  // Back into the image: stretch the radial component of the centre again.
  const double along = cx * ux + cy * uy;
  const double grow = (radial_stretch - 1.0) * along;
  out.x_px = blob.x_px + cx + grow * ux;
  out.y_px = blob.y_px + cy + grow * uy;
  out.radius_px = rad;
  out.inliers = inl;
  out.rms_px = std::sqrt(ss / std::max(inl, 1));
  out.ok = true;
  return out;
}

}  // namespace mocap::detect
