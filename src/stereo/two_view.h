// Design: optimal two-view triangulation (Lindstrom 2010, "Triangulation made easy",
// the two-iteration scheme niter2) and the linear DLT baseline.
// Geometry of an ordered camera pair is precomputed once (StereoGeometry). The
// optimisation runs on *pixel-scaled undistorted* coordinates s = (fx x', fy y')
// (x' = normalised undistorted), so the corrected points minimise the sum of squared
// distances in undistorted pixels, the 2D optimum of the two-view reprojection error.
// The fundamental matrix F_s between these coordinates satisfies
//   [s1; 1]^T F_s [s0; 1] = 0,  F_s = D1^-1 [t_10]x R_10 D0^-1,  Dk = diag(fxk, fyk, 1).
// Everything here is noexcept and allocation-free (fixed-size Eigen only).
#pragma once

#include "camera/camera_model.h"
#include "core/expected.h"
#include "core/types.h"

namespace mocap {

struct StereoGeometry {
  double fx0 = 1.0, fy0 = 1.0, fx1 = 1.0, fy1 = 1.0;  // focal lengths, px
  Mat3 R_0w = Mat3::Identity();  // camera 0 extrinsics: X_cam0 = R_0w * X_world + t_0w
  Vec3 t_0w = Vec3::Zero();
  Mat3 R_10;            // X_cam1 = R_10 * X_cam0 + t_10
  Vec3 t_10;            // mm
  Mat3 F_s;             // epipolar constraint between pixel-scaled coordinates
  Vec3 baseline_dir_0;  // unit vector from centre 0 to centre 1, camera-0 frame
  double baseline_mm = 0.0;
};

// Setup: fails (one-line error) on a zero baseline or non-positive focal lengths.
Expected<StereoGeometry> make_stereo_geometry(const CameraModel& cam0, const CameraModel& cam1);
// The same without validation (noexcept, no allocation); false on a zero baseline.
bool compute_stereo_geometry(const CameraModel& cam0, const CameraModel& cam1,
                             StereoGeometry& g) noexcept;

// Pixel-scaled coordinates of a normalised undistorted point (principal point dropped:
// a shift does not change distances).
inline Vec2 to_scaled(const CameraModel& cam, const Vec2& xn) noexcept {
  return Vec2(cam.fx * xn.x(), cam.fy * xn.y());
}
inline Vec2 from_scaled(const CameraModel& cam, const Vec2& s) noexcept {
  return Vec2(s.x() / cam.fx, s.y() / cam.fy);
}

// Symmetric epipolar distances (undistorted pixels) of a pair of pixel-scaled points:
// d0 = distance of s0 to the epipolar line of s1 in image 0, d1 likewise in image 1.
void epipolar_distances_px(const StereoGeometry& g, const Vec2& s0, const Vec2& s1, double& d0,
                           double& d1) noexcept;

// Lindstrom's niter2: corrects pixel-scaled points (s0, s1) to (s0c, s1c) that satisfy
// the epipolar constraint and minimise |s0-s0c|^2 + |s1-s1c|^2. niter2's two steps
// are followed by up to max_polish_iterations fixed-point steps until converged to
// 1e-10 px (0: the paper's niter2 alone).
void niter2_correct(const Mat3& F_s, const Vec2& s0, const Vec2& s1, Vec2& s0c, Vec2& s1c,
                    int max_polish_iterations = 10) noexcept;

// Depths of a corrected pair: intersects the rays of the (corrected) normalised points
// in camera-0 coordinates. Returns false when the rays are parallel (point at infinity
// or on the baseline). X_cam0 in mm.
bool intersect_rays(const StereoGeometry& g, const Vec2& xn0c, const Vec2& xn1c,
                    Vec3& X_cam0) noexcept;

// Optimal triangulation from normalised undistorted coordinates (xn = (x', y')).
// Returns false for degenerate rays or a point behind either camera (cheirality).
bool triangulate_niter2(const StereoGeometry& g, const Vec2& xn0, const Vec2& xn1,
                        Vec3& X_world) noexcept;
// Convenience form for one-off use (computes the pair geometry on the stack per call).
bool triangulate_niter2(const CameraModel& c0, const CameraModel& c1, const Vec2& xn0,
                        const Vec2& xn1, Vec3& X_world) noexcept;

// From distorted pixels: undistorts both, triangulates with niter2 and reports the RMS
// reprojection error over the two views in the real images (project()). False when an
// undistortion fails, the rays are parallel or the point is behind a camera.
bool triangulate_pixels(const StereoGeometry& g, const CameraModel& c0, const CameraModel& c1,
                        const Vec2& px0, const Vec2& px1, Vec3& X_world,
                        double& reproj_px) noexcept;

// Linear (DLT, homogeneous SVD) triangulation from normalised undistorted
// coordinates; the baseline for benchmarks and the start of N-view refinement.
bool triangulate_dlt(const StereoGeometry& g, const Vec2& xn0, const Vec2& xn1,
                     Vec3& X_world) noexcept;

// RMS over the two views of the reprojection error in the real (distorted) images, px.
// Returns false when X projects behind a camera.
bool reprojection_rms_px(const CameraModel& c0, const CameraModel& c1, const Vec3& X_world,
                         const Vec2& px0, const Vec2& px1, double& rms_px) noexcept;

}  // namespace mocap
