// Design: N-view triangulation building blocks for rigs with more than two cameras:
// a linear (DLT) estimate from normalised undistorted coordinates, then Gauss-Newton
// on the reprojection error in the real (distorted) pixels, using project()'s 2x3
// Jacobian. Fixed maximum size (kMaxCameras): noexcept, no allocation.
#pragma once

#include "camera/camera_model.h"
#include "core/types.h"
#include "stereo/stereo_types.h"

namespace mocap {

// cams[k], xn[k] for k < n, 2 <= n <= kMaxCameras. The world frame is recentred on
// the mean optical centre and scaled by the mean centre distance before the SVD.
// Returns false for n out of range, a degenerate system or a point behind a camera.
bool triangulate_linear_nview(const CameraModel* const* cams, const Vec2* xn, int n,
                              Vec3& X_world) noexcept;

// Minimises sum_k |project(cams[k], X) - px[k]|^2 starting from X_world (in/out).
// Stops when a step is below step_tolerance_mm or after max_iterations. Writes the final
// RMS reprojection error (px) and, when r2_px is non-null, each view's squared
// reprojection error at the returned X_world (r2_px[k], px^2; the same evaluation as the
// RMS). Returns false when a camera sees the point behind it.
bool refine_gauss_newton(const CameraModel* const* cams, const Vec2* px, int n, Vec3& X_world,
                         double& rms_px, int max_iterations = 10, double step_tolerance_mm = 1e-9,
                         double* r2_px = nullptr) noexcept;

}  // namespace mocap
