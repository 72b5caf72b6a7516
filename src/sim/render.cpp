// Design: render() itself (see render.h for the image formation model). Steps:
//  1. markers and capsules into the camera frame, silhouette boxes, random drop-outs;
//  2. per marker patch: each pixel is classified against the nearby spheres' angular
//     radii (outside all -> no signal; near an edge -> supersample_edge^2 samples;
//     inside -> supersample_interior^2 samples); each sample's ray takes the nearest
//     sphere/capsule hit, a ball hit gives peak * (a + (1 - a) cos(incidence));
//  3. stray reflections; 4. Gaussian blur over the patches; 5. background + noise over
//  the whole image from a quantile table, then exact Gaussian read + shot noise on
//  patch pixels, rounding and clipping; 6. merged flags. Stamps make overlapping
//  patches render each pixel once.
#include "sim/render.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>

#include "sim/render_detail.h"
#include "sim/sim_rng.h"

namespace mocap::sim {
namespace {

using detail::clip_rect;
using detail::intersects;

constexpr int kMaxHits = 64;

struct PixelCorners {
  double x00, y00, x10, y10, x01, y01, x11, y11;
};

// Integrates the marker signal over one pixel (mean over its samples).
float pixel_signal(const SimScene& scene, RenderWorkspace& ws, const PixelCorners& pc,
                   int n_spheres, int n_capsules) noexcept {
  const ImagingParams& im = scene.imaging;
  // Classify the pixel from its centre ray.
  Vec3 dc(0.25 * (pc.x00 + pc.x10 + pc.x01 + pc.x11), 0.25 * (pc.y00 + pc.y10 + pc.y01 + pc.y11),
          1.0);
  dc.normalize();
  bool touched = false, edge = false;
  for (int k = 0; k < n_spheres; ++k) {
    const auto j = static_cast<std::size_t>(ws.cand_spheres[static_cast<std::size_t>(k)]);
    const Vec3& c = ws.sphere_c[j];
    const double cos_ang = dc.dot(c) / c.norm();
    if (cos_ang >= ws.sphere_cos_out[j]) {
      touched = true;
      if (cos_ang < ws.sphere_cos_in[j]) edge = true;
    }
  }
  if (!touched) return 0.0f;
  const int S = edge ? im.supersample_edge : im.supersample_interior;
  const double w = 1.0 / (S * S);
  const double r = scene.marker_radius_mm;
  const double cc_r = r * r;
  const double a_limb = im.limb_factor;
  double sum = 0.0;
  std::array<int, kMaxHits> hits{};
  for (int sy = 0; sy < S; ++sy) {
    const double v = (sy + 0.5) / S;
    const double lx = pc.x00 + v * (pc.x01 - pc.x00), rx = pc.x10 + v * (pc.x11 - pc.x10);
    const double ly = pc.y00 + v * (pc.y01 - pc.y00), ry = pc.y10 + v * (pc.y11 - pc.y10);
    for (int sx = 0; sx < S; ++sx) {
      const double u = (sx + 0.5) / S;
      Vec3 d(lx + u * (rx - lx), ly + u * (ry - ly), 1.0);
      d.normalize();
      double best_t = 1e300, best_sq = 0.0;
      int best = -1, n_hits = 0;
      for (int k = 0; k < n_spheres; ++k) {
        const int j = ws.cand_spheres[static_cast<std::size_t>(k)];
        const Vec3& c = ws.sphere_c[static_cast<std::size_t>(j)];
        const double b = d.dot(c);
        const double disc = b * b - (c.squaredNorm() - cc_r);
        if (disc <= 0.0) continue;
        const double sq = std::sqrt(disc);
        const double t = b - sq;
        if (t <= 0.0) continue;
        if (n_hits < kMaxHits) hits[static_cast<std::size_t>(n_hits++)] = j;
        if (t < best_t) {
          best_t = t;
          best_sq = sq;
          best = j;
        }
      }
      if (best < 0) continue;
      for (int k = 0; k < n_hits; ++k) {
        const int j = hits[static_cast<std::size_t>(k)];
        if (j != best) ws.markers[static_cast<std::size_t>(j)].occluded_area_px += w;
      }
      bool occluded = false;
      for (int k = 0; k < n_capsules && !occluded; ++k) {
        const auto q = static_cast<std::size_t>(ws.cand_capsules[static_cast<std::size_t>(k)]);
        const double t =
            detail::ray_capsule(d, ws.capsule_a[q], ws.capsule_b[q], scene.capsules[q].radius_mm);
        occluded = t > 0.0 && t < best_t;
      }
      MarkerView& mv = ws.markers[static_cast<std::size_t>(best)];
      if (occluded) {
        mv.occluded_area_px += w;
      } else {
        mv.visible_area_px += w;
        const double cos_inc = std::min(1.0, best_sq / r);
        sum += ws.sphere_peak[static_cast<std::size_t>(best)] * (a_limb + (1.0 - a_limb) * cos_inc);
      }
    }
  }
  return static_cast<float>(sum * w);
}

void render_marker_patch(const SimScene& scene, RenderWorkspace& ws, int cam_index,
                         const PixelRect& patch, std::uint32_t id) noexcept {
  const int n_markers = scene.marker_count();
  int n_s = 0, n_c = 0;
  for (int j = 0; j < n_markers; ++j) {
    const MarkerView& mv = ws.markers[static_cast<std::size_t>(j)];
    if (mv.in_front && !mv.dropped && intersects(ws.sphere_box[static_cast<std::size_t>(j)], patch))
      ws.cand_spheres[static_cast<std::size_t>(n_s++)] = j;
  }
  for (std::size_t q = 0; q < scene.capsules.size(); ++q) {
    if (intersects(ws.capsule_box[q], patch))
      ws.cand_capsules[static_cast<std::size_t>(n_c++)] = static_cast<int>(q);
  }
  const RenderWorkspace::Lattice& lat = ws.lattices[static_cast<std::size_t>(cam_index)];
  const int W = lat.width;
  const auto lw = static_cast<std::size_t>(W + 1);
  for (int y = patch.y0; y <= patch.y1; ++y) {
    for (int x = patch.x0; x <= patch.x1; ++x) {
      const std::size_t p =
          static_cast<std::size_t>(y) * static_cast<std::size_t>(W) + static_cast<std::size_t>(x);
      if (ws.stamp[p] == id) continue;
      ws.stamp[p] = id;
      const std::size_t c00 = static_cast<std::size_t>(y) * lw + static_cast<std::size_t>(x);
      const PixelCorners pc{lat.xn[c00],          lat.yn[c00],         lat.xn[c00 + 1],
                            lat.yn[c00 + 1],      lat.xn[c00 + lw],    lat.yn[c00 + lw],
                            lat.xn[c00 + lw + 1], lat.yn[c00 + lw + 1]};
      ws.signal[p] = pixel_signal(scene, ws, pc, n_s, n_c);
    }
  }
}

void blur_patches(RenderWorkspace& ws, int W, int H) noexcept {
  const int kr = ws.blur_radius;
  const float* k = ws.blur_kernel.data() + kr;  // k[-kr..kr]
  for (int i = 0; i < ws.patch_count; ++i) {
    const PixelRect& r = ws.patches[static_cast<std::size_t>(i)];
    const int ya = std::max(0, r.y0 - kr), yb = std::min(H - 1, r.y1 + kr);
    for (int y = ya; y <= yb; ++y) {
      const float* src = ws.signal.data() + static_cast<std::ptrdiff_t>(y) * W;
      float* dst = ws.tmp.data() + static_cast<std::ptrdiff_t>(y) * W;
      for (int x = r.x0; x <= r.x1; ++x) {
        float acc = 0.0f;
        for (int o = -kr; o <= kr; ++o) {
          const int xx = x + o;
          if (xx >= 0 && xx < W) acc += k[o] * src[xx];
        }
        dst[x] = acc;
      }
    }
    for (int y = r.y0; y <= r.y1; ++y) {
      float* dst = ws.blurred.data() + static_cast<std::ptrdiff_t>(y) * W;
      for (int x = r.x0; x <= r.x1; ++x) {
        float acc = 0.0f;
        for (int o = -kr; o <= kr; ++o) {
          const int yy = y + o;
          if (yy >= 0 && yy < H)
            acc += k[o] * ws.tmp[static_cast<std::size_t>(yy) * static_cast<std::size_t>(W) +
                                 static_cast<std::size_t>(x)];
        }
        dst[x] = acc;
      }
    }
  }
}

void fill_background(RenderWorkspace& ws, Rng& rng, Image& out) noexcept {
  const std::uint16_t* table = ws.background_table.data();
  const int W = out.width(), H = out.height();
  const bool is8 = out.format() == PixelFormat::kMono8;
  for (int y = 0; y < H; ++y) {
    std::uint8_t* row8 = out.row8(y);
    std::uint16_t* row16 = out.row16(y);
    for (int x = 0; x < W; x += 4) {
      std::uint64_t bits = rng.next();
      const int n = std::min(4, W - x);
      for (int i = 0; i < n; ++i, bits >>= 16) {
        const std::uint16_t v = table[bits & 0xFFFFu];
        if (is8) {
          row8[x + i] = static_cast<std::uint8_t>(v);
        } else {
          row16[x + i] = v;
        }
      }
    }
  }
}

void noise_patches(const SimScene& scene, RenderWorkspace& ws, Rng& rng, const float* signal,
                   std::uint32_t id, Image& out) noexcept {
  const ImagingParams& im = scene.imaging;
  const int W = out.width();
  const bool is8 = out.format() == PixelFormat::kMono8;
  const double maxval = im.maxval;
  const double read2 = im.read_noise_dn * im.read_noise_dn;
  for (int i = 0; i < ws.patch_count; ++i) {
    const PixelRect& r = ws.patches[static_cast<std::size_t>(i)];
    for (int y = r.y0; y <= r.y1; ++y) {
      for (int x = r.x0; x <= r.x1; ++x) {
        const std::size_t p =
            static_cast<std::size_t>(y) * static_cast<std::size_t>(W) + static_cast<std::size_t>(x);
        if (ws.stamp[p] == id) continue;
        ws.stamp[p] = id;
        const double v = im.background_dn + static_cast<double>(signal[p]);
        const double sigma = std::sqrt(read2 + im.shot_gain_dn_per_e * std::max(v, 0.0));
        const double q = std::clamp(std::nearbyint(v + sigma * rng.gaussian()), 0.0, maxval);
        if (is8) {
          out.row8(y)[x] = static_cast<std::uint8_t>(q);
        } else {
          out.row16(y)[x] = static_cast<std::uint16_t>(q);
        }
      }
    }
  }
}

void mark_merged(const SimScene& scene, RenderWorkspace& ws) noexcept {
  const int n = scene.marker_count();
  const double blur3 = 3.0 * scene.imaging.blur_sigma_px;
  const double gap_px = 2.0 + 2.0 * blur3;
  for (int i = 0; i < n; ++i) {
    MarkerView& a = ws.markers[static_cast<std::size_t>(i)];
    a.merged = false;
    if (!a.in_front || a.dropped || a.visible_area_px <= 0.0) continue;
    for (int j = 0; j < n && !a.merged; ++j) {
      const MarkerView& b = ws.markers[static_cast<std::size_t>(j)];
      if (j == i || !b.in_front || b.dropped || b.visible_area_px <= 0.0) continue;
      a.merged = (a.disc_center_px - b.disc_center_px).norm() <
                 a.disc_radius_px + b.disc_radius_px + gap_px;
    }
    for (int s = 0; s < ws.stray_count && !a.merged; ++s) {
      const double reach = a.disc_radius_px + gap_px + 4.0;  // a glint's lobes reach ~4 px
      a.merged = (a.disc_center_px - ws.strays[static_cast<std::size_t>(s)].px).norm() < reach;
    }
  }
}

}  // namespace

bool render(const SimScene& scene, const SceneState& state, int camera_index, RenderWorkspace& ws,
            Image& out) noexcept {
  if (camera_index < 0 || camera_index >= static_cast<int>(scene.rig.cameras.size())) return false;
  if (state.T_world_body.size() != scene.targets.bodies.size()) return false;
  if (ws.markers.size() != static_cast<std::size_t>(scene.marker_count()) ||
      ws.lattices.size() != scene.rig.cameras.size())
    return false;
  const CameraModel& cam = scene.rig.cameras[static_cast<std::size_t>(camera_index)];
  const PixelFormat want = scene.imaging.bits == 8 ? PixelFormat::kMono8 : PixelFormat::kMono16;
  if (out.width() != cam.width || out.height() != cam.height || out.format() != want ||
      out.maxval() != scene.imaging.maxval)
    return false;
  const int W = cam.width, H = cam.height;
  if (ws.stamp.size() < static_cast<std::size_t>(W) * static_cast<std::size_t>(H)) return false;
  if (ws.stamp_id > 0xFFFFFF00u) {
    std::fill(ws.stamp.begin(), ws.stamp.end(), 0u);
    ws.stamp_id = 0;
  }
  const std::uint32_t id_signal = ++ws.stamp_id;
  const std::uint32_t id_noise = ++ws.stamp_id;
  const std::uint64_t cam_key =
      hash_mix(state.noise_key, static_cast<std::uint64_t>(camera_index) + 1);
  const ImagingParams& im = scene.imaging;
  const double r = scene.marker_radius_mm;
  const int grow = ws.blur_radius + 1;

  // 1. Geometry in the camera frame.
  ws.patch_count = 0;
  ws.stray_count = 0;
  for (int m = 0; m < scene.marker_count(); ++m) {
    const auto um = static_cast<std::size_t>(m);
    MarkerView& mv = ws.markers[um];
    mv = MarkerView{};
    const Vec3 X_world = state.T_world_body[static_cast<std::size_t>(scene.marker_body[um])] *
                         scene.marker_in_body(m);
    const Vec3 c = cam.R_cam_world * X_world + cam.t_cam_world;
    ws.sphere_c[um] = c;
    double u0, u1, v0, v1;
    mv.in_front = project(cam, X_world, mv.center_px) &&
                  detail::sphere_silhouette(cam, c, r, 16, u0, u1, v0, v1, mv.disc_center_px,
                                            mv.disc_radius_px);
    if (!mv.in_front) {
      ws.sphere_box[um] = PixelRect{};
      continue;
    }
    mv.inside_image = u0 >= 0.0 && v0 >= 0.0 && u1 <= W - 1.0 && v1 <= H - 1.0;
    mv.dropped =
        im.dropout_probability > 0.0 &&
        hash_uniform(hash_mix(hash_mix(cam_key, 0x64726F70ull), um)) < im.dropout_probability;
    const double dist = c.norm();
    const double alpha = std::asin(std::min(1.0, r / dist));
    ws.sphere_cos_out[um] = std::cos(std::min(alpha + ws.edge_margin_rad, 3.0));
    ws.sphere_cos_in[um] = alpha > ws.edge_margin_rad ? std::cos(alpha - ws.edge_margin_rad) : 2.0;
    const double rel = im.reference_distance_mm / dist;
    ws.sphere_peak[um] = im.marker_peak_dn * rel * rel;
    ws.sphere_box[um] = detail::cover_rect(u0, u1, v0, v1, 1);
  }
  for (std::size_t q = 0; q < scene.capsules.size(); ++q) {
    const Capsule& cap = scene.capsules[q];
    const Iso3& T = state.T_world_body[static_cast<std::size_t>(cap.body)];
    ws.capsule_a[q] = cam.R_cam_world * (T * cap.a_body) + cam.t_cam_world;
    ws.capsule_b[q] = cam.R_cam_world * (T * cap.b_body) + cam.t_cam_world;
    // Box of the silhouettes of spheres along the axis (ends, quarters, middle): a
    // straight limb bows under lens distortion, so its ends alone do not bound it.
    double bu0 = 1e300, bu1 = -1e300, bv0 = 1e300, bv1 = -1e300;
    bool ok = true;
    for (int k = 0; k <= 4 && ok; ++k) {
      const Vec3 p = ws.capsule_a[q] + 0.25 * k * (ws.capsule_b[q] - ws.capsule_a[q]);
      double u0 = 0.0, u1 = 0.0, v0 = 0.0, v1 = 0.0, rad = 0.0;
      Vec2 cen;
      ok = detail::sphere_silhouette(cam, p, cap.radius_mm, 8, u0, u1, v0, v1, cen, rad);
      bu0 = std::min(bu0, u0);
      bu1 = std::max(bu1, u1);
      bv0 = std::min(bv0, v0);
      bv1 = std::max(bv1, v1);
    }
    ws.capsule_box[q] = ok ? detail::cover_rect(bu0, bu1, bv0, bv1, 3)
                           : PixelRect{-1000000, -1000000, 1000000, 1000000};
  }

  // 2. Marker patches.
  for (int m = 0; m < scene.marker_count(); ++m) {
    const auto um = static_cast<std::size_t>(m);
    const MarkerView& mv = ws.markers[um];
    if (!mv.in_front || mv.dropped) continue;
    const PixelRect& b = ws.sphere_box[um];
    const PixelRect patch =
        clip_rect(PixelRect{b.x0 - grow, b.y0 - grow, b.x1 + grow, b.y1 + grow}, W, H);
    if (patch.empty()) continue;
    ws.patches[static_cast<std::size_t>(ws.patch_count++)] = patch;
    render_marker_patch(scene, ws, camera_index, patch, id_signal);
  }

  // 3. Stray reflections.
  detail::draw_strays(scene, state, cam, ws);

  // 4. Optical blur.
  const float* signal = ws.signal.data();
  if (ws.blur_radius > 0) {
    blur_patches(ws, W, H);
    signal = ws.blurred.data();
  }

  // 5. Background, noise, quantisation.
  Rng rng(hash_mix(cam_key, 0x6E6F697365ull));
  fill_background(ws, rng, out);
  noise_patches(scene, ws, rng, signal, id_noise, out);
  for (int i = 0; i < ws.patch_count; ++i) {
    const PixelRect& pr = ws.patches[static_cast<std::size_t>(i)];
    for (int y = pr.y0; y <= pr.y1; ++y) {
      float* row = ws.signal.data() + static_cast<std::ptrdiff_t>(y) * W;
      std::fill(row + pr.x0, row + pr.x1 + 1, 0.0f);
    }
  }

  // 6. Which discs touch another disc or a stray reflection.
  mark_merged(scene, ws);
  return true;
}

Image make_camera_image(const SimScene& scene, int camera_index) {
  const CameraModel& cam = scene.rig.cameras[static_cast<std::size_t>(camera_index)];
  return Image(cam.width, cam.height,
               scene.imaging.bits == 8 ? PixelFormat::kMono8 : PixelFormat::kMono16,
               static_cast<std::uint16_t>(scene.imaging.maxval));
}

}  // namespace mocap::sim
