// Design: relative pose of a calibrated camera pair from point correspondences, in
// normalised undistorted coordinates (x', y'). RANSAC over the normalised 8-point
// algorithm (Hartley's isotropic scaling, rank-2 projection of E onto singular values
// (1, 1, 0)), scored by the Sampson distance; the consensus set is refitted linearly and
// E is decomposed into the four (R, t) candidates, of which the one that puts most
// inliers in front of both cameras wins. t has unit length (the scale comes from the
// wand). Setup-time code: allocates, deterministic for a given seed.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "core/expected.h"
#include "core/types.h"

namespace mocap::rigcal {

struct RelativePose {
  Mat3 R_1_0 = Mat3::Identity();  // X_cam1 = R_1_0 X_cam0 + t_1_0
  Vec3 t_1_0 = Vec3::UnitX();     // unit length
  Mat3 E = Mat3::Zero();
  std::vector<bool> inlier;
  int inlier_count = 0;
};

struct EssentialOptions {
  double threshold = 2e-3;  // Sampson distance in normalised units (~2.5 px at f = 1290)
  int iterations = 500;
  std::uint64_t seed = 1;
};

// E from >= 8 correspondences (least squares), rank-2 projected. False if degenerate.
bool essential_8point(std::span<const Vec2> x0, std::span<const Vec2> x1, Mat3& E);

// First-order (Sampson) distance of a correspondence to E, normalised units.
double sampson_distance(const Mat3& E, const Vec2& x0, const Vec2& x1) noexcept;

// Linear triangulation in the camera-0 frame for pose (R, t).
Vec3 triangulate_linear(const Mat3& R_1_0, const Vec3& t_1_0, const Vec2& x0, const Vec2& x1);

Expected<RelativePose> estimate_relative_pose(std::span<const Vec2> x0, std::span<const Vec2> x1,
                                              const EssentialOptions& options);

}  // namespace mocap::rigcal
