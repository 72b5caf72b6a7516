// Design: the physically based renderer of one camera's image of one scene state.
// Each marker is the image of a sphere: for every sub-pixel sample the pixel position
// is undistorted (undistort_pixel, evaluated exactly on the pixel-corner lattice at
// setup and interpolated bilinearly inside the pixel), turned into a ray, and
// intersected with every nearby sphere and capsule; the nearest hit wins. Only pixel
// patches around each marker's projected silhouette (and around stray reflections) are
// rendered; the rest of the image is the background level plus noise.
// Order of effects: pixel-area integration -> Gaussian blur -> read + shot noise ->
// rounding and clipping at maxval. Every random draw derives from the state's
// noise_key and the camera index, so a render is deterministic and order-independent.
// render() is noexcept and allocation-free: all buffers live in a RenderWorkspace
// created at setup (the pattern f(const Model&, Workspace&, in, out&)).
#pragma once

#include <cstdint>
#include <vector>

#include "core/expected.h"
#include "core/image.h"
#include "sim/scene.h"

namespace mocap::sim {

// What render() found about one marker in the camera it rendered last.
struct MarkerView {
  Vec2 center_px = Vec2::Zero();       // project() of the sphere centre
  Vec2 disc_center_px = Vec2::Zero();  // centre of the projected silhouette's bounding circle
  double disc_radius_px = 0.0;         // radius of that circle
  double visible_area_px = 0.0;        // rendered area where this ball is the nearest hit
  double occluded_area_px = 0.0;       // area where the ball is hit but something is nearer
  bool in_front = false;
  bool dropped = false;       // random drop-out: not rendered at all
  bool inside_image = false;  // the whole silhouette lies inside the image
  bool merged = false;        // its disc touches another visible disc or a stray reflection
  // Visible, not dropped, inside the image, not occluded at all, not merged.
  bool isolated() const noexcept {
    return in_front && !dropped && inside_image && occluded_area_px == 0.0 &&
           visible_area_px > 0.0 && !merged;
  }
};

enum class StrayKind : std::uint8_t { kGlint, kStreak };

// One stray reflection drawn in the last render (a streak is a chain of points).
struct StrayView {
  StrayKind kind = StrayKind::kGlint;
  Vec3 X_world = Vec3::Zero();
  Vec2 px = Vec2::Zero();
  double peak_dn = 0.0;
};

struct PixelRect {
  int x0 = 0, y0 = 0, x1 = -1, y1 = -1;  // inclusive
  bool empty() const noexcept { return x1 < x0 || y1 < y0; }
};

// Preallocated buffers of render(). Members are internal to the renderer except the
// read-only results: markers (one per scene marker) and strays[0, stray_count).
struct RenderWorkspace {
  static Expected<RenderWorkspace> create(const SimScene& scene);

  std::vector<MarkerView> markers;
  std::vector<StrayView> strays;
  int stray_count = 0;

  // Internal.
  struct Lattice {
    int width = 0, height = 0;
    std::vector<double> xn;  // (width+1) x (height+1) corners: undistorted normalised x, y
    std::vector<double> yn;
  };
  std::vector<Lattice> lattices;  // one per camera
  std::vector<float> signal, tmp, blurred;
  std::vector<std::uint32_t> stamp;
  std::uint32_t stamp_id = 0;
  std::vector<std::uint16_t> background_table;  // 65536 quantiles of the background noise
  std::vector<float> blur_kernel;
  int blur_radius = 0;
  std::vector<Vec3> sphere_c;  // camera frame
  std::vector<double> sphere_peak, sphere_cos_in, sphere_cos_out;
  std::vector<PixelRect> sphere_box;
  std::vector<Vec3> capsule_a, capsule_b;  // camera frame
  std::vector<PixelRect> capsule_box;
  std::vector<PixelRect> patches;
  int patch_count = 0;
  std::vector<int> cand_spheres, cand_capsules;
  double edge_margin_rad = 0.0;
};

// Renders camera `camera_index`'s image of `state` into `out`, which must already have
// the camera's size and the scene's format (kMono8 for 8 bits, else kMono16) and maxval.
// False (out untouched or partial) on a mismatch.
bool render(const SimScene& scene, const SceneState& state, int camera_index, RenderWorkspace& ws,
            Image& out) noexcept;

// An Image of the right size and format for render() (setup; allocates).
Image make_camera_image(const SimScene& scene, int camera_index);

}  // namespace mocap::sim
