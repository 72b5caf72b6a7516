// Design: measurement helpers of the simulator tests, written independently of the
// renderer and of the tracker's modules: a background-subtracted centroid of the blob
// around a given pixel, and a two-view triangulation (midpoint, then Gauss-Newton on
// the reprojection error) using only the camera model.
#pragma once

#include <cmath>
#include <vector>

#include "camera/camera_model.h"
#include "core/image.h"

namespace mocap::test {

inline double pixel_at(const ImageView& im, int x, int y) {
  return im.format == PixelFormat::kMono8 ? im.row8(y)[x] : im.row16(y)[x];
}

// Centroid of the connected region of pixels above `threshold` containing the pixel
// nearest to `seed`, grown by `dilate` pixels, with weights pixel - background.
// Returns false when the seed pixel is not above the threshold.
inline bool blob_centroid(const ImageView& im, const Vec2& seed, double threshold,
                          double background, int dilate, Vec2& centroid, int* region_px = nullptr) {
  const int sx = static_cast<int>(std::lround(seed.x())),
            sy = static_cast<int>(std::lround(seed.y()));
  if (sx < 0 || sy < 0 || sx >= im.width || sy >= im.height) return false;
  if (pixel_at(im, sx, sy) <= threshold) return false;
  std::vector<unsigned char> in(
      static_cast<std::size_t>(im.width) * static_cast<std::size_t>(im.height), 0);
  std::vector<std::pair<int, int>> stack{{sx, sy}};
  auto idx = [&](int x, int y) {
    return static_cast<std::size_t>(y) * static_cast<std::size_t>(im.width) +
           static_cast<std::size_t>(x);
  };
  in[idx(sx, sy)] = 1;
  std::vector<std::pair<int, int>> region;
  while (!stack.empty()) {
    auto [x, y] = stack.back();
    stack.pop_back();
    region.emplace_back(x, y);
    for (auto [dx, dy] : {std::pair{1, 0}, std::pair{-1, 0}, std::pair{0, 1}, std::pair{0, -1}}) {
      const int nx = x + dx, ny = y + dy;
      if (nx < 0 || ny < 0 || nx >= im.width || ny >= im.height || in[idx(nx, ny)]) continue;
      if (pixel_at(im, nx, ny) > threshold) {
        in[idx(nx, ny)] = 1;
        stack.emplace_back(nx, ny);
      }
    }
  }
  for (const auto& [x, y] : region) {
    for (int dy = -dilate; dy <= dilate; ++dy) {
      for (int dx = -dilate; dx <= dilate; ++dx) {
        const int nx = x + dx, ny = y + dy;
        if (nx >= 0 && ny >= 0 && nx < im.width && ny < im.height && !in[idx(nx, ny)])
          in[idx(nx, ny)] = 2;
      }
    }
  }
  double sw = 0.0, su = 0.0, sv = 0.0;
  int n = 0;
  for (int y = 0; y < im.height; ++y) {
    for (int x = 0; x < im.width; ++x) {
      if (!in[idx(x, y)]) continue;
      const double w = pixel_at(im, x, y) - background;
      sw += w;
      su += w * x;
      sv += w * y;
      ++n;
    }
  }
  if (region_px) *region_px = n;
  if (!(sw > 0.0)) return false;
  centroid = Vec2(su / sw, sv / sw);
  return true;
}

// Triangulates one point seen at pixel p0 in c0 and p1 in c1.
inline bool triangulate(const CameraModel& c0, const CameraModel& c1, const Vec2& p0,
                        const Vec2& p1, Vec3& X) {
  Vec3 d0, d1;
  if (!pixel_ray_world(c0, p0, d0) || !pixel_ray_world(c1, p1, d1)) return false;
  const Vec3 o0 = c0.center_world(), o1 = c1.center_world();
  // Midpoint of the closest points of the two rays.
  const Vec3 w = o0 - o1;
  const double a = d0.dot(d0), b = d0.dot(d1), c = d1.dot(d1), d = d0.dot(w), e = d1.dot(w);
  const double den = a * c - b * b;
  if (std::abs(den) < 1e-12) return false;
  const double s = (b * e - c * d) / den, t = (a * e - b * d) / den;
  X = 0.5 * ((o0 + s * d0) + (o1 + t * d1));
  // Gauss-Newton on the pixel reprojection error of both views.
  for (int it = 0; it < 10; ++it) {
    Eigen::Matrix<double, 4, 3> J;
    Eigen::Matrix<double, 4, 1> r;
    Vec2 q0, q1;
    Eigen::Matrix<double, 2, 3> J0, J1;
    if (!project(c0, X, q0, J0) || !project(c1, X, q1, J1)) return false;
    r << q0 - p0, q1 - p1;
    J << J0, J1;
    const Vec3 dx = (J.transpose() * J).ldlt().solve(-J.transpose() * r);
    X += dx;
    if (dx.norm() < 1e-10) break;
  }
  return true;
}

}  // namespace mocap::test
