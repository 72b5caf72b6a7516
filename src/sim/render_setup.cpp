// Design: setup of the renderer's workspace (allocates, returns Expected): the exact
// undistortion of every pixel corner of every camera (undistort_pixel, so that the
// sample rays inside a pixel are a bilinear interpolation of exact rays: the error is
// below 1e-5 px for the simulated lenses, tested), the blur kernel (the Gaussian PSF
// integrated over each pixel), and the background table: 65536 equally likely
// quantised values of background + N(0, read^2 + gain * background), so that the
// background of a whole image costs one table look-up per pixel.
#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>

#include "sim/render.h"

namespace mocap::sim {
namespace {

// Inverse of the standard normal CDF: Acklam's rational approximation refined by one
// Halley step on std::erfc (full double precision).
double inverse_normal_cdf(double p) {
  static const double a[] = {-3.969683028665376e+01, 2.209460984245205e+02,  -2.759285104469687e+02,
                             1.383577518672690e+02,  -3.066479806614716e+01, 2.506628277459239e+00};
  static const double b[] = {-5.447609879822406e+01, 1.615858368580409e+02, -1.556989798598866e+02,
                             6.680131188771972e+01, -1.328068155288572e+01};
  static const double c[] = {-7.784894002430293e-03, -3.223964580411365e-01, -2.400758277161838e+00,
                             -2.549732539343734e+00, 4.374664141464968e+00,  2.938163982698783e+00};
  static const double d[] = {7.784695709041462e-03, 3.224671290700398e-01, 2.445134137142996e+00,
                             3.754408661907416e+00};
  double x = 0.0;
  if (p < 0.02425) {
    const double q = std::sqrt(-2.0 * std::log(p));
    x = (((((c[0] * q + c[1]) * q + c[2]) * q + c[3]) * q + c[4]) * q + c[5]) /
        ((((d[0] * q + d[1]) * q + d[2]) * q + d[3]) * q + 1.0);
  } else if (p > 1.0 - 0.02425) {
    const double q = std::sqrt(-2.0 * std::log(1.0 - p));
    x = -(((((c[0] * q + c[1]) * q + c[2]) * q + c[3]) * q + c[4]) * q + c[5]) /
        ((((d[0] * q + d[1]) * q + d[2]) * q + d[3]) * q + 1.0);
  } else {
    const double q = p - 0.5;
    const double r = q * q;
    x = (((((a[0] * r + a[1]) * r + a[2]) * r + a[3]) * r + a[4]) * r + a[5]) * q /
        (((((b[0] * r + b[1]) * r + b[2]) * r + b[3]) * r + b[4]) * r + 1.0);
  }
  const double e = 0.5 * std::erfc(-x / std::numbers::sqrt2) - p;
  const double u = e * std::sqrt(2.0 * std::numbers::pi) * std::exp(x * x / 2.0);
  return x - u / (1.0 + x * u / 2.0);
}

}  // namespace

Expected<RenderWorkspace> RenderWorkspace::create(const SimScene& scene) {
  RenderWorkspace ws;
  const auto n_markers = static_cast<std::size_t>(scene.marker_count());
  if (n_markers == 0 || n_markers > 256)
    return make_error("simulate", "markers", "need 1..256 markers");
  int max_w = 0, max_h = 0;
  double min_f = 1e300;
  for (const CameraModel& cam : scene.rig.cameras) {
    if (cam.width <= 0 || cam.height <= 0)
      return make_error("simulate", cam.name, "image size must be positive");
    Lattice lat;
    lat.width = cam.width;
    lat.height = cam.height;
    const auto n =
        static_cast<std::size_t>(cam.width + 1) * static_cast<std::size_t>(cam.height + 1);
    lat.xn.resize(n);
    lat.yn.resize(n);
    for (int j = 0; j <= cam.height; ++j) {
      for (int i = 0; i <= cam.width; ++i) {
        Vec2 xn;
        if (!undistort_pixel(cam, Vec2(i - 0.5, j - 0.5), xn)) {
          return make_error("simulate", cam.name,
                            "distortion not invertible at pixel (" + std::to_string(i) + ", " +
                                std::to_string(j) + ")");
        }
        const std::size_t k =
            static_cast<std::size_t>(j) * static_cast<std::size_t>(cam.width + 1) +
            static_cast<std::size_t>(i);
        lat.xn[k] = xn.x();
        lat.yn[k] = xn.y();
      }
    }
    ws.lattices.push_back(std::move(lat));
    max_w = std::max(max_w, cam.width);
    max_h = std::max(max_h, cam.height);
    min_f = std::min({min_f, cam.fx, cam.fy});
  }
  const auto n_px = static_cast<std::size_t>(max_w) * static_cast<std::size_t>(max_h);
  ws.signal.assign(n_px, 0.0f);
  ws.tmp.assign(n_px, 0.0f);
  ws.blurred.assign(n_px, 0.0f);
  ws.stamp.assign(n_px, 0u);
  // Angular margin of the pixel classification: 1.5 pixel widths (covers the pixel's
  // half-diagonal and the lens's local magnification).
  ws.edge_margin_rad = 1.5 / min_f;

  const ImagingParams& im = scene.imaging;
  const double sigma = im.blur_sigma_px;
  if (sigma >= 0.05) {
    ws.blur_radius = static_cast<int>(std::ceil(3.0 * sigma));
    double sum = 0.0;
    for (int i = -ws.blur_radius; i <= ws.blur_radius; ++i) {
      const double s2 = sigma * std::numbers::sqrt2;
      const double k = 0.5 * (std::erf((i + 0.5) / s2) - std::erf((i - 0.5) / s2));
      ws.blur_kernel.push_back(static_cast<float>(k));
      sum += k;
    }
    for (float& k : ws.blur_kernel) k = static_cast<float>(static_cast<double>(k) / sum);
  } else {
    ws.blur_radius = 0;
    ws.blur_kernel.assign(1, 1.0f);
  }

  ws.background_table.resize(65536);
  const double bg_sigma =
      std::sqrt(im.read_noise_dn * im.read_noise_dn + im.shot_gain_dn_per_e * im.background_dn);
  for (std::size_t i = 0; i < ws.background_table.size(); ++i) {
    const double p = (static_cast<double>(i) + 0.5) / 65536.0;
    const double v = std::nearbyint(im.background_dn + bg_sigma * inverse_normal_cdf(p));
    ws.background_table[i] =
        static_cast<std::uint16_t>(std::clamp(v, 0.0, static_cast<double>(im.maxval)));
  }

  ws.markers.assign(n_markers, MarkerView{});
  ws.strays.assign(scene.glints.size() + 512, StrayView{});
  ws.sphere_c.assign(n_markers, Vec3::Zero());
  ws.sphere_peak.assign(n_markers, 0.0);
  ws.sphere_cos_in.assign(n_markers, 2.0);
  ws.sphere_cos_out.assign(n_markers, 2.0);
  ws.sphere_box.assign(n_markers, PixelRect{});
  ws.capsule_a.assign(scene.capsules.size(), Vec3::Zero());
  ws.capsule_b.assign(scene.capsules.size(), Vec3::Zero());
  ws.capsule_box.assign(scene.capsules.size(), PixelRect{});
  ws.patches.assign(n_markers + scene.glints.size() + 2, PixelRect{});
  ws.cand_spheres.assign(n_markers, 0);
  ws.cand_capsules.assign(scene.capsules.size(), 0);
  return ws;
}

}  // namespace mocap::sim
