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

// An edge point in a fit: the sample, whether the fit keeps it, and whether it lies on
// an AxisSide::kChecked side's axial arc.
struct FitPoint {
  double x, y, sigma;
  int ray;
  bool inlier;
  bool checked;
};

struct CircleFit {
  bool ok = false;
  double cx = 0.0, cy = 0.0, rad = 0.0, rms = 0.0;
  int inliers = 0;
  Eigen::Matrix2d cov = Eigen::Matrix2d::Zero();  // the centre's (unstretched frame)
};

// The robust circle fit over the edge points (the checked ones only with use_checked).
CircleFit fit_circle(const FitPoint* all, int n_all, bool use_checked, int rays, int min_inliers,
                     double contrast_dn, double noise, const EdgeCentreConfig& cfg) noexcept {
  CircleFit out;
  std::array<FitPoint, kMaxEdgeRays> pts{};
  int n = 0;
  for (int i = 0; i < n_all; ++i)
    if (use_checked || !all[i].checked) pts[static_cast<std::size_t>(n++)] = all[i];
  if (n < min_inliers) return out;

  // Kasa's fit over all points: x^2 + y^2 + D x + E y + F = 0.
  Eigen::Matrix3d A = Eigen::Matrix3d::Zero();
  Eigen::Vector3d b = Eigen::Vector3d::Zero();
  for (int i = 0; i < n; ++i) {
    const FitPoint& q = pts[static_cast<std::size_t>(i)];
    const Eigen::Vector3d row(q.x, q.y, 1.0);
    A += row * row.transpose();
    b -= row * (q.x * q.x + q.y * q.y);
  }
  const Eigen::FullPivLU<Eigen::Matrix3d> kasa(A);
  if (!kasa.isInvertible()) return out;
  const Eigen::Vector3d p = kasa.solve(b);
  double cx = -0.5 * p[0], cy = -0.5 * p[1];
  const double rad2 = cx * cx + cy * cy - p[2];
  if (!(rad2 > 0.0)) return out;
  double rad = std::sqrt(rad2);

  std::array<double, kMaxEdgeRays> abs_res{};
  std::array<double, kMaxEdgeRays> sig{};
  int inl = 0;
  Eigen::Matrix3d H = Eigen::Matrix3d::Zero();
  for (int iter = 0; iter < 8; ++iter) {
    // Robust scale: the median edge noise, or the points' own spread (MAD), the larger.
    for (int i = 0; i < n; ++i) {
      const FitPoint& q = pts[static_cast<std::size_t>(i)];
      abs_res[static_cast<std::size_t>(i)] = std::fabs(std::hypot(q.x - cx, q.y - cy) - rad);
      sig[static_cast<std::size_t>(i)] = q.sigma;
    }
    const auto un = static_cast<std::size_t>(n);
    const double sigma_median = median_in_place(sig.data(), un);
    const double scale = std::max(1.4826 * median_in_place(abs_res.data(), un), sigma_median);
    // A hidden part darkens the edge beyond itself by the blur: the rays within one edge
    // width (contrast / gradient, the median over the rays) of a rejected ray's edge point
    // along the rim are rejected with it.
    const double edge_width_px = contrast_dn * sigma_median / noise;
    const int spread =
        std::min(rays / 4, static_cast<int>(std::ceil(cfg.hidden_spread_widths * edge_width_px *
                                                      rays / (2.0 * M_PI * std::max(rad, 0.5)))));
    std::array<bool, kMaxEdgeRays> hidden{};
    for (int i = 0; i < n; ++i) {
      FitPoint& q = pts[static_cast<std::size_t>(i)];
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
        const FitPoint& q = pts[static_cast<std::size_t>(i)];
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
      FitPoint& q = pts[static_cast<std::size_t>(i)];
      q.inlier = q.inlier && !hidden[static_cast<std::size_t>(q.ray)];
      inl += q.inlier ? 1 : 0;
    }
    if (inl < min_inliers) return out;
    // One Gauss-Newton step on the geometric residual |q - c| - rad.
    H.setZero();
    Eigen::Vector3d g = Eigen::Vector3d::Zero();
    for (int i = 0; i < n; ++i) {
      const FitPoint& q = pts[static_cast<std::size_t>(i)];
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
    const FitPoint& q = pts[static_cast<std::size_t>(i)];
    if (!q.inlier) continue;
    const double e = std::hypot(q.x - cx, q.y - cy) - rad;
    ss += e * e;
  }
  const Eigen::FullPivLU<Eigen::Matrix3d> info(H);
  if (!info.isInvertible()) return out;
  // Residual variance per point, and the rays' correlation: neighbouring rays closer than
  // a pixel along the rim read the same pixels (about one independent sample per pixel).
  const double var = ss / std::max(inl - 3, 1);
  const double rim_spacing_px = 2.0 * M_PI * rad / rays;
  const double correlation = std::max(1.0, 1.0 / rim_spacing_px);
  out.cov = var * correlation * info.inverse().topLeftCorner<2, 2>();
  out.cx = cx;
  out.cy = cy;
  out.rad = rad;
  out.inliers = inl;
  out.rms = std::sqrt(ss / std::max(inl, 1));
  out.ok = true;
  return out;
}

}  // namespace

bool sample_edge(const ImageView& img, const Blob& blob, double noise_dn, double radial_x,
                 double radial_y, double radial_stretch, const EdgeCentreConfig& cfg,
                 EdgeSamples& out) noexcept {
  out.count = 0;
  out.rays = std::clamp(cfg.rays, 8, kMaxEdgeRays);
  const double bg = blob.background_dn, peak = blob.peak_dn;
  out.noise_dn = std::max(noise_dn, 0.5);  // a quantisation floor for noiseless images
  out.contrast_dn = peak - bg;
  if (img.empty() || !(out.contrast_dn > cfg.min_contrast_sigmas * out.noise_dn)) return false;
  if (!(radial_stretch > 0.2 && radial_stretch < 5.0)) radial_stretch = 1.0;
  const double rn = std::hypot(radial_x, radial_y);
  out.ux = rn > 0.0 ? radial_x / rn : 1.0;
  out.uy = rn > 0.0 ? radial_y / rn : 0.0;
  out.stretch = radial_stretch;
  out.x0_px = blob.x_px;
  out.y0_px = blob.y_px;
  const double level = bg + cfg.level * out.contrast_dn;
  const double r_max = 0.5 * std::max(blob.x_max - blob.x_min, blob.y_max - blob.y_min) + 3.0;
  const double step = std::clamp(cfg.step_px, 0.05, 1.0);
  double centre = 0.0;
  if (!sample_bilinear(img, blob.x_px, blob.y_px, centre) || centre < level) return false;
  for (int k = 0; k < out.rays; ++k) {
    const double a = 2.0 * M_PI * k / out.rays;
    const double dx = std::cos(a), dy = std::sin(a);
    double prev = centre;
    for (double r = step; r <= r_max; r += step) {
      double v = 0.0;
      if (!sample_bilinear(img, blob.x_px + r * dx, blob.y_px + r * dy, v)) break;
      if (v < level) {
        const double t = (prev - level) / (prev - v);  // in (0, 1]
        const double re = r - step + t * step;
        const double grad = (prev - v) / step;  // DN per px, > 0
        const double ex = re * dx, ey = re * dy;
        // Unstretch: divide the radial component by the stretch.
        const double along = ex * out.ux + ey * out.uy;
        const double shrink = (1.0 / radial_stretch - 1.0) * along;
        out.points[static_cast<std::size_t>(out.count++)] = {
            ex + shrink * out.ux, ey + shrink * out.uy, out.noise_dn / std::max(grad, 1e-9), k};
        break;
      }
      prev = v;
    }
  }
  return true;
}

EdgeCentre fit_edge_centre(const EdgeSamples& s, const EdgeCentreConfig& cfg,
                           EdgeAxis axis) noexcept {
  EdgeCentre out;
  out.edge_points = s.count;
  if (s.count <= 0 || s.rays < 8) return out;
  const int rays = s.rays;
  // An occluder axis: the rays within a side's half angle of it on an occluded side are
  // not used; on a checked side they are marked.
  const double an = std::hypot(axis.x, axis.y);
  const double ax = an > 0.0 ? axis.x / an : 0.0, ay = an > 0.0 ? axis.y / an : 0.0;
  auto cos_half = [&](double deg) {
    return an > 0.0 ? std::cos(std::clamp(deg, 0.0, 70.0) * M_PI / 180.0) : 2.0;
  };
  const double cos_forward = cos_half(axis.forward_half_angle_deg);
  const double cos_backward = cos_half(axis.backward_half_angle_deg);
  auto side_of = [&](int k) -> const AxisSide* {
    const double a = 2.0 * M_PI * k / rays;
    const double c_axis = std::cos(a) * ax + std::sin(a) * ay;
    return c_axis > cos_forward ? &axis.forward : -c_axis > cos_backward ? &axis.backward : nullptr;
  };
  int core_rays = 0, checked_rays = 0;
  for (int k = 0; k < rays; ++k) {
    const AxisSide* side = side_of(k);
    if (!side)
      ++core_rays;
    else if (*side == AxisSide::kChecked)
      ++checked_rays;
  }
  std::array<FitPoint, kMaxEdgeRays> pts{};
  int n = 0, n_checked = 0;
  for (int i = 0; i < s.count; ++i) {
    const EdgePoint& e = s.points[static_cast<std::size_t>(i)];
    const AxisSide* side = side_of(e.ray);
    if (side && *side == AxisSide::kOccluded) continue;
    pts[static_cast<std::size_t>(n++)] = {e.x, e.y, e.sigma, e.ray, true, side != nullptr};
    n_checked += side != nullptr ? 1 : 0;
  }
  auto min_inliers = [&](int used_rays) {
    return std::max(6, static_cast<int>(std::ceil(cfg.min_inlier_fraction * used_rays)));
  };
  CircleFit fit = fit_circle(pts.data(), n, false, rays, min_inliers(core_rays), s.contrast_dn,
                             s.noise_dn, cfg);
  if (!fit.ok) return out;
  const double ux = s.ux, uy = s.uy, radial_stretch = s.stretch;
  if (n_checked > 0) {
    // The checked side's rays, taken when they do not move the centre along the axis by
    // more than check_sigmas of the difference of the two nested fits.
    const CircleFit full =
        fit_circle(pts.data(), n, true, rays, min_inliers(core_rays + checked_rays), s.contrast_dn,
                   s.noise_dn, cfg);
    if (full.ok) {
      // The axis in the unstretched frame (its radial component divided by the stretch).
      const double a_along = ax * ux + ay * uy;
      const double s_ax = ax + (1.0 / radial_stretch - 1.0) * a_along * ux;
      const double s_ay = ay + (1.0 / radial_stretch - 1.0) * a_along * uy;
      const Eigen::Vector2d u_axis = Eigen::Vector2d(s_ax, s_ay).normalized();
      const double var_core = u_axis.dot(fit.cov * u_axis);
      const double var_full = u_axis.dot(full.cov * u_axis);
      const double var_diff = std::max(var_core - var_full, 0.25 * var_core);
      const double shift = u_axis.dot(Eigen::Vector2d(full.cx - fit.cx, full.cy - fit.cy));
      if (std::fabs(shift) <= cfg.check_sigmas * std::sqrt(var_diff)) {
        fit = full;
        out.checked_used = true;
      }
    }
  }
  // Back into the image: stretch the radial component of the centre (and of its
  // covariance) again.
  const double along = fit.cx * ux + fit.cy * uy;
  const double grow = (radial_stretch - 1.0) * along;
  out.x_px = s.x0_px + fit.cx + grow * ux;
  out.y_px = s.y0_px + fit.cy + grow * uy;
  const Eigen::Vector2d u(ux, uy);
  const Eigen::Matrix2d J =
      Eigen::Matrix2d::Identity() + (radial_stretch - 1.0) * u * u.transpose();
  out.cov_px2 = J * fit.cov * J.transpose();
  out.radius_px = fit.rad;
  out.inliers = fit.inliers;
  out.rms_px = fit.rms;
  out.ok = true;
  return out;
}

EdgeCentre edge_centre(const ImageView& img, const Blob& blob, double noise_dn, double radial_x,
                       double radial_y, double radial_stretch, const EdgeCentreConfig& cfg,
                       EdgeAxis axis) noexcept {
  EdgeSamples samples;
  if (!sample_edge(img, blob, noise_dn, radial_x, radial_y, radial_stretch, cfg, samples))
    return {};
  return fit_edge_centre(samples, cfg, axis);
}

}  // namespace mocap::detect
