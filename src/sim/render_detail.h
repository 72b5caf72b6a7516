// Design: internal helpers of the renderer (not a public API): ray intersections for
// rays from the camera centre (the camera frame's origin) with unit direction d, the
// projected bounding box of a sphere's silhouette, and the stray-reflection pass.
// All noexcept and allocation-free.
#pragma once

#include <algorithm>
#include <cmath>
#include <limits>

#include "camera/camera_model.h"
#include "sim/render.h"

namespace mocap::sim::detail {

// Distance along the unit ray d to the first intersection with the capsule (segment
// pa-pb, radius r), or a negative number when the ray misses it.
inline double ray_capsule(const Vec3& d, const Vec3& pa, const Vec3& pb, double r) noexcept {
  const Vec3 ba = pb - pa;
  const Vec3 oa = -pa;
  const double baba = ba.dot(ba);
  const double bard = ba.dot(d);
  const double baoa = ba.dot(oa);
  const double rdoa = d.dot(oa);
  const double oaoa = oa.dot(oa);
  const double a = baba - bard * bard;
  if (a > 1e-12 * baba) {
    const double b = baba * rdoa - baoa * bard;
    const double c = baba * oaoa - baoa * baoa - r * r * baba;
    const double h = b * b - a * c;
    if (h < 0.0) return -1.0;
    const double t = (-b - std::sqrt(h)) / a;
    const double y = baoa + t * bard;
    if (y > 0.0 && y < baba) return t;
    const Vec3 oc = (y <= 0.0) ? oa : Vec3(-pb);
    const double b2 = d.dot(oc);
    const double h2 = b2 * b2 - (oc.dot(oc) - r * r);
    return h2 > 0.0 ? -b2 - std::sqrt(h2) : -1.0;
  }
  // Ray parallel to the axis: only the end caps can be hit first.
  double best = -1.0;
  for (const Vec3* p : {&pa, &pb}) {
    const double b2 = d.dot(*p);
    const double h2 = b2 * b2 - (p->squaredNorm() - r * r);
    if (h2 > 0.0) {
      const double t = b2 - std::sqrt(h2);
      if (t > 0.0 && (best < 0.0 || t < best)) best = t;
    }
  }
  return best;
}

// Pixel bounds of the silhouette of a sphere (centre c in the camera frame, radius r),
// sampled at n points of its tangent circle; also the centre and radius of the
// circle bounding the sampled silhouette. False when the sphere is not in front.
inline bool sphere_silhouette(const CameraModel& cam, const Vec3& c, double r, int n, double& u_min,
                              double& u_max, double& v_min, double& v_max, Vec2& center_px,
                              double& radius_px) noexcept {
  if (!(c.z() > r + 1.0)) return false;
  const double d2 = c.squaredNorm();
  const Vec3 q = c * (1.0 - r * r / d2);
  const double rho = r * std::sqrt(d2 - r * r) / std::sqrt(d2);
  const Vec3 axis = c.normalized();
  const Vec3 e1 = axis.unitOrthogonal();
  const Vec3 e2 = axis.cross(e1);
  u_min = v_min = std::numeric_limits<double>::max();
  u_max = v_max = -std::numeric_limits<double>::max();
  Vec2 sum = Vec2::Zero();
  Vec2 pts[32];
  const int m = std::min(n, 32);
  for (int k = 0; k < m; ++k) {
    const double ang = 2.0 * 3.14159265358979323846 * k / m;
    const Vec3 p = q + rho * (std::cos(ang) * e1 + std::sin(ang) * e2);
    if (!(p.z() > 1e-6)) return false;
    const Vec2 px = normalized_to_pixel(cam, Vec2(p.x() / p.z(), p.y() / p.z()));
    pts[k] = px;
    sum += px;
    u_min = std::min(u_min, px.x());
    u_max = std::max(u_max, px.x());
    v_min = std::min(v_min, px.y());
    v_max = std::max(v_max, px.y());
  }
  center_px = sum / m;
  radius_px = 0.0;
  for (int k = 0; k < m; ++k) radius_px = std::max(radius_px, (pts[k] - center_px).norm());
  return true;
}

// Pixel rectangle covering [u_min, u_max] x [v_min, v_max] grown by `grow` pixels.
inline PixelRect cover_rect(double u_min, double u_max, double v_min, double v_max,
                            int grow) noexcept {
  auto fl = [](double x) {
    return static_cast<int>(std::floor(std::clamp(x, -1.0e6, 1.0e6) + 0.5));
  };
  return PixelRect{fl(u_min) - grow, fl(v_min) - grow, fl(u_max) + grow, fl(v_max) + grow};
}

inline bool intersects(const PixelRect& a, const PixelRect& b) noexcept {
  return !(a.x1 < b.x0 || b.x1 < a.x0 || a.y1 < b.y0 || b.y1 < a.y0);
}

inline PixelRect clip_rect(const PixelRect& r, int width, int height) noexcept {
  return PixelRect{std::max(r.x0, 0), std::max(r.y0, 0), std::min(r.x1, width - 1),
                   std::min(r.y1, height - 1)};
}

// Adds the glints and the optional streak to ws.signal, appends their patches and
// fills ws.strays. Runs after the markers' pixel signals are in ws.signal.
void draw_strays(const SimScene& scene, const SceneState& state, const CameraModel& cam,
                 RenderWorkspace& ws) noexcept;

}  // namespace mocap::sim::detail
