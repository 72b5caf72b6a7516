// Design: is a blob the image of a WHOLE marker ball? (partial-marker classification)
// The prediction comes from the physics, not from one renderer:
//  1. Silhouette: the ball (radius rho = marker_diameter / 2, centre C in camera
//     coordinates) is seen through the pinhole as the cone of rays at angle alpha from
//     C (sin alpha = rho / |C|). On the normalised undistorted plane z = 1 that cone is
//     an exact ellipse (a conic); its centre x0 and shape matrix S follow in closed form.
//  2. Lens: the ellipse is mapped to pixels by the local Jacobian of the full camera
//     model at x0 (J = diag(fx, fy) * d(distort)/d(x') — distortion included), so the
//     predicted covariance of a uniformly filled silhouette is Sigma_g = J (S / 4) J^T.
//  3. Comparison: the detector's weighted second moments Sigma_m (major/minor axes and
//     orientation) of any radially symmetric brightness profile on that silhouette,
//     blurred by any isotropic PSF, equal k * Sigma_g + b * I with unknown k in
//     (0, 1] (profile, threshold) and b >= 0 (PSF, pixel area). Only the traceless
//     (anisotropic) part is profile-free: D_m must equal k * D_g for some k in
//     [0, tr(Sigma_m) / tr(Sigma_g)]. The residual, normalised by tr(Sigma_m) / 2, is
//     compared with a tolerance derived from pixelisation (threshold cut of the edge
//     pixels), the image noise and the linearisation of the distortion over the blob
//     (derivation in docs/detection.md, "Whole or partial marker").
//  4. Two views: a marker is whole only when its 3D point's predicted silhouette agrees
//     with its blob in BOTH cameras (occlusion is view-dependent).
// Flagged blobs (border, merged, split, truncated) are never whole.
// Setup validates and copies the cameras; classify() is noexcept and allocation-free.
#pragma once

#include <array>
#include <cstdint>

#include "camera/camera_model.h"
#include "core/expected.h"
#include "core/types.h"
#include "detect/blob.h"

namespace mocap {

struct MarkerShapeConfig {
  bool enabled = true;
  // False-partial probability per view for a whole marker under the Gaussian model of
  // the moments' noise (sets z of the Rayleigh tail: z = sqrt(-2 ln p), 5.26 for 1e-6).
  // The design point is deliberately far out: the detector's noise estimate is the
  // background's, and the shot noise of the bright pixels widens the real tails.
  double false_partial_probability = 1e-6;
};

// What the image of a detector frame says about its noise (DetectorCounters last_*).
struct ImageNoise {
  double background_dn = 0.0;
  double noise_dn = 0.0;      // per-pixel sigma
  double threshold_dn = 0.0;  // pixels below were not part of the blob's moments
};

struct ShapeCheck {
  bool whole = false;
  double residual = 0.0;   // normalised anisotropy mismatch (dimensionless)
  double tolerance = 0.0;  // what the physics allows for this blob
};

class MarkerShapeModel {
 public:
  static Expected<MarkerShapeModel> create(const CameraModel& cam, double marker_diameter_mm,
                                           const MarkerShapeConfig& config);

  // Predicted silhouette covariance (pixels^2) and centre (pixels) of a ball at X_world.
  // False when the ball is behind the camera or contains the pinhole.
  bool predict(const Vec3& X_world, Eigen::Matrix2d& Sigma_px, Vec2& center_px) const noexcept;

  // One view of one marker.
  ShapeCheck check(const detect::Blob& blob, const Vec3& X_world,
                   const ImageNoise& noise) const noexcept;

  bool enabled() const noexcept { return config_.enabled; }

  // Visible fraction of the ball's silhouette in this view, in [0, 1]: the ratio r of the
  // blob's thresholded area to the predicted silhouette's (4 pi sqrt(det Sigma_g)), or
  // 1/r when r > 1 (light merged in from elsewhere misplaces as much mass); 0 for
  // a flagged blob (border, merged, split, truncated: its centroid is not a cut disc's)
  // or when there is no prediction (the worst case). See partial_centroid_shift().
  double visible_fraction(const detect::Blob& blob, const Vec3& X_world) const noexcept;

 private:
  // The silhouette ellipse on the normalised undistorted plane: shape S, centre x0.
  bool silhouette(const Vec3& X_world, Eigen::Matrix2d& S, Vec2& x0,
                  double& dist_mm) const noexcept;
  double linearisation_error(const Eigen::Matrix2d& S, const Vec2& x0) const noexcept;

  CameraModel cam_;
  double radius_mm_ = 6.0;
  double z_ = 4.3;
  MarkerShapeConfig config_;
};

// Centroid shift of a partly hidden disc, in units of its radius, for a visible fraction
// f in [0, 1]: the disc cut by a straight edge (the rim of a nearer limb or ball is much
// larger than the marker, so locally straight). Removing the segment beyond a chord at
// distance d from the centre (segment area A_s = acos d - d sqrt(1 - d^2), centroid at
// 2 (1 - d^2)^(3/2) / (3 A_s)) moves the centroid of the rest by
//   b = 2 (1 - d^2)^(3/2) / (3 (pi - A_s)),   f = 1 - A_s / pi.
// b(1) = 0, b(1/2) = 4 / (3 pi) = 0.42, b -> 1 as f -> 0 (a thin sliver at the rim).
// For a given hidden area the straight cut moves the centroid farthest (its removed
// mass lies farthest out), so b(f) bounds the bias of any convex occluder's cut.
double partial_centroid_shift(double visible_fraction) noexcept;

// The measured weighted covariance (pixels^2) of a blob from its axes and orientation.
Eigen::Matrix2d blob_covariance_px(const detect::Blob& blob) noexcept;

}  // namespace mocap
