// Design: stray reflections (optional), drawn into the signal before blur and noise.
//  - Glints: small shiny spots (screw heads) on the limbs. With the light coaxial to
//    the camera, a spot reflects towards the camera with brightness
//    peak * cos(normal, view)^glint_exponent; it is hidden when it faces away or when a
//    ball or limb lies on the ray. Its image is an irregular blob of up to three
//    Gaussian lobes (a shape fixed per spot) at the spot's projection.
//  - Streak: the specular line of a polished cylinder (the lower arm) lies where the
//    surface normal points at the camera: P(s) = axis(s) + radius * n(s). It is drawn as
//    a chain of Gaussian footprints (line density normalised so its peak is
//    streak_peak_dn times the tube's sin(axis, view)^2), occluded point by point.
#include <algorithm>
#include <cmath>

#include "sim/render_detail.h"

namespace mocap::sim::detail {
namespace {

// True when the segment from the camera to p_cam (camera frame) is blocked by a ball or
// a capsule other than at p itself.
bool occluded(const SimScene& scene, const RenderWorkspace& ws, const Vec3& p_cam) noexcept {
  const double t_p = p_cam.norm();
  const Vec3 d = p_cam / t_p;
  const double r = scene.marker_radius_mm;
  for (int m = 0; m < scene.marker_count(); ++m) {
    const MarkerView& mv = ws.markers[static_cast<std::size_t>(m)];
    if (!mv.in_front || mv.dropped) continue;
    const Vec3& c = ws.sphere_c[static_cast<std::size_t>(m)];
    const double b = d.dot(c);
    const double disc = b * b - (c.squaredNorm() - r * r);
    if (disc > 0.0 && b - std::sqrt(disc) < t_p - 0.5) return true;
  }
  for (std::size_t q = 0; q < scene.capsules.size(); ++q) {
    const double t = ray_capsule(d, ws.capsule_a[q], ws.capsule_b[q], scene.capsules[q].radius_mm);
    if (t > 0.0 && t < t_p - 0.5) return true;
  }
  return false;
}

void deposit(RenderWorkspace& ws, int W, int H, double u, double v, double amp,
             double sigma) noexcept {
  const int rad = static_cast<int>(std::ceil(3.5 * sigma));
  const int cx = static_cast<int>(std::floor(u + 0.5)), cy = static_cast<int>(std::floor(v + 0.5));
  const double inv = 1.0 / (2.0 * sigma * sigma);
  for (int y = std::max(0, cy - rad); y <= std::min(H - 1, cy + rad); ++y) {
    for (int x = std::max(0, cx - rad); x <= std::min(W - 1, cx + rad); ++x) {
      const double dx = x - u, dy = y - v;
      ws.signal[static_cast<std::size_t>(y) * static_cast<std::size_t>(W) +
                static_cast<std::size_t>(x)] +=
          static_cast<float>(amp * std::exp(-(dx * dx + dy * dy) * inv));
    }
  }
}

void add_patch(RenderWorkspace& ws, double u_min, double u_max, double v_min, double v_max,
               int grow, int W, int H) noexcept {
  if (ws.patch_count >= static_cast<int>(ws.patches.size())) return;
  const PixelRect r = clip_rect(cover_rect(u_min, u_max, v_min, v_max, grow), W, H);
  if (!r.empty()) ws.patches[static_cast<std::size_t>(ws.patch_count++)] = r;
}

void push_stray(RenderWorkspace& ws, StrayKind kind, const Vec3& X_world, const Vec2& px,
                double peak) noexcept {
  if (ws.stray_count >= static_cast<int>(ws.strays.size())) return;
  ws.strays[static_cast<std::size_t>(ws.stray_count++)] = StrayView{kind, X_world, px, peak};
}

}  // namespace

void draw_strays(const SimScene& scene, const SceneState& state, const CameraModel& cam,
                 RenderWorkspace& ws) noexcept {
  const int W = cam.width, H = cam.height;
  const ImagingParams& im = scene.imaging;
  const int grow = ws.blur_radius + 1;
  const Vec3 cam_center = cam.center_world();
  for (const GlintSpot& g : scene.glints) {
    const Iso3& T = state.T_world_body[static_cast<std::size_t>(g.body)];
    const Vec3 P = T * g.point_body;
    const Vec3 n = T.linear() * g.normal_body;
    const double ndv = n.dot((cam_center - P).normalized());
    if (ndv <= 0.0) continue;
    const double peak = g.peak_dn * std::pow(ndv, im.glint_exponent);
    if (peak < 2.0 * im.read_noise_dn) continue;
    const Vec3 p_cam = cam.R_cam_world * P + cam.t_cam_world;
    Vec2 px;
    if (!project(cam, P, px) || occluded(scene, ws, p_cam)) continue;
    if (px.x() < -10.0 || px.y() < -10.0 || px.x() > W + 10.0 || px.y() > H + 10.0) continue;
    static constexpr double kAmp[3] = {1.0, 0.7, 0.5};
    double reach = 0.0;
    for (int k = 0; k < 3; ++k) {
      const Vec3& lobe = g.lobes[static_cast<std::size_t>(k)];
      deposit(ws, W, H, px.x() + lobe.x(), px.y() + lobe.y(), peak * kAmp[k], lobe.z());
      reach = std::max(reach, std::max(std::abs(lobe.x()), std::abs(lobe.y())) + 3.5 * lobe.z());
    }
    add_patch(ws, px.x() - reach, px.x() + reach, px.y() - reach, px.y() + reach, grow, W, H);
    push_stray(ws, StrayKind::kGlint, P, px, peak);
  }
  if (!im.streak) return;
  for (std::size_t q = 0; q < scene.capsules.size(); ++q) {
    const Capsule& cap = scene.capsules[q];
    if (!cap.shiny) continue;
    const Vec3& A = ws.capsule_a[q];
    const Vec3& B = ws.capsule_b[q];
    Vec2 pa, pb;
    if (!(A.z() > 1.0 && B.z() > 1.0)) continue;
    pa = normalized_to_pixel(cam, Vec2(A.x() / A.z(), A.y() / A.z()));
    pb = normalized_to_pixel(cam, Vec2(B.x() / B.z(), B.y() / B.z()));
    const double len_px = (pb - pa).norm();
    const int steps = std::clamp(static_cast<int>(std::ceil(2.0 * len_px)), 8, 2048);
    const Vec3 axis = (B - A).normalized();
    const double s0 = 0.1, s1 = 0.9;
    const double spacing_px = len_px * (s1 - s0) / steps;
    const double sigma = im.streak_sigma_px;
    const double line_norm = spacing_px / (std::sqrt(2.0 * 3.14159265358979323846) * sigma);
    const int record_every =
        std::max(1, static_cast<int>(std::round(5.0 / std::max(spacing_px, 1e-3))));
    double u_min = 1e300, u_max = -1e300, v_min = 1e300, v_max = -1e300;
    const Iso3 T_world_cam = cam.T_cam_world().inverse();
    for (int k = 0; k < steps; ++k) {
      const double s = s0 + (s1 - s0) * (k + 0.5) / steps;
      const Vec3 X = A + s * (B - A);
      const Vec3 w = -X.normalized();
      const Vec3 wp = w - w.dot(axis) * axis;
      if (wp.norm() < 1e-9) continue;
      const Vec3 P = X + cap.radius_mm * wp.normalized();
      if (!(P.z() > 1.0) || occluded(scene, ws, P)) continue;
      const double shine = 1.0 - w.dot(axis) * w.dot(axis);
      const Vec2 px = normalized_to_pixel(cam, Vec2(P.x() / P.z(), P.y() / P.z()));
      if (px.x() < -10.0 || px.y() < -10.0 || px.x() > W + 10.0 || px.y() > H + 10.0) continue;
      deposit(ws, W, H, px.x(), px.y(), im.streak_peak_dn * shine * line_norm, sigma);
      u_min = std::min(u_min, px.x());
      u_max = std::max(u_max, px.x());
      v_min = std::min(v_min, px.y());
      v_max = std::max(v_max, px.y());
      if (k % record_every == 0)
        push_stray(ws, StrayKind::kStreak, T_world_cam * P, px, im.streak_peak_dn * shine);
    }
    if (u_min <= u_max) {
      const double reach = 3.5 * sigma;
      add_patch(ws, u_min - reach, u_max + reach, v_min - reach, v_max + reach, grow, W, H);
    }
  }
}

}  // namespace mocap::sim::detail
