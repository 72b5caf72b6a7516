// Design: the centre of a marker ball's image from its silhouette edge, for when the
// intensity centroid is biased because part of the ball is hidden: a calibration wand's
// rod (or handle) enters each ball, and from every viewpoint on the side it points to
// it covers a notch of the ball's rim. The centroid then moves away from the notch by a
// fraction of a pixel, always along the wand: a bias that no number of frames averages
// out and that sets a wand-calibrated rig's scale wrong (docs/rig_calibration.md,
// "Partly hidden wand balls").
//
// Method: from the blob's centroid, `rays` rays sample the image (bilinear) outwards
// and each finds where the signal first falls below half the blob's peak above the
// background (the half level of a radially symmetric profile, whatever its shape or
// blur). The edge points are mapped through the shape a whole ball has at that place
// (an ellipse stretched or squeezed along the radial direction of the image, the
// caller's `radial_stretch` from the lens model) to a circle, and a circle is fitted
// to them robustly: the notch's points lie inside the circle and are rejected at
// `inlier_sigmas` times the edge noise, which is derived from the image noise and the
// edge's own intensity gradient (sigma_edge = noise_dn / |dI/dr|), never below the
// spread of the points themselves (MAD). The centre is mapped back into the image.
// Known occluder axis: when the caller knows the line along which an occluder enters
// the ball (a wand's rod and handle run along the wand), the rays within
// the side's half angle of that axis on an occluded side are not used at all: the rim
// there may be hidden by an amount too small to reject (a thin rod's blurred flank), and
// whatever bias it leaves points along the axis. With both sides occluded (a middle
// ball) the two remaining arcs are symmetric about the axis, so the fitted radius cannot
// trade against the centre's position along it. A wand's end ball has the rod on one
// side only; its outer side (AxisSide::kChecked) may have a handle, so the centre is
// fitted without that side's axial rays and with them, and the fuller fit is taken when
// its centre lies within check_sigmas of the other one (the sigma of the difference of
// two nested fits: sqrt(var_without - var_with) along the axis). The outer rim then
// restores much of the precision along the wand, the direction that sets a wand-
// calibrated rig's scale. How wide the occluded side's cut must be depends on the rod
// (its diameter over the ball's) and the blur; rigcal/wand_centres.h chooses it per
// recording. The default, 45 degrees, leaves out the rim a rod up to 0.7 x the ball's
// radius hides in a sharp image, or up to ~0.4 x when the blur spans 20 degrees of the
// rim (a ball 3 px in radius).
// Two steps: sample_edge() finds the edge points once; fit_edge_centre() fits them, as
// often as the caller wants with other axes or cuts (edge_centre() does both).
// Not ok (use the centroid): a faint blob, too few edge points, or too few inliers.
// No allocation (fixed arrays); setup/offline code (the rig calibration), not the
// tracker's hot path.
#pragma once

#include <Eigen/Core>
#include <array>

#include "core/image.h"
#include "detect/blob.h"

namespace mocap::detect {

struct EdgeCentreConfig {
  int rays = 64;                      // 8..kMaxEdgeRays
  double level = 0.5;                 // fraction of (peak - background) that marks the edge
  double inlier_sigmas = 3.0;         // residual limit, in edge-noise sigmas
  double min_contrast_sigmas = 10.0;  // peak - background below this x noise: not ok
  double min_inlier_fraction = 0.5;   // of the rays
  double step_px = 0.25;              // sampling step along a ray
  double hidden_spread_widths = 1.0;  // rays rejected beside a rejected one, in edge widths
  bool grow_hidden = true;            // and further while the next ray's point is > 1 sigma inside
  double check_sigmas = 3.0;          // AxisSide::kChecked: the shift allowed, in its sigmas
};

// What lies on one side of an occluder axis (EdgeAxis).
enum class AxisSide : unsigned char {
  kOccluded,  // an occluder (a wand's rod): the rays within the side's half angle are not used
  kChecked,   // maybe one (a wand's handle beyond an end ball): the rays are used only when
              // the centre they move stays within check_sigmas of the centre without them
};

// An occluder axis in the image (any length; zero: none), what lies on its two sides,
// and how far from the axis (half angle at the centre) each side's rim is affected.
struct EdgeAxis {
  double x = 0.0, y = 0.0;
  AxisSide forward = AxisSide::kOccluded;   // the side the vector points to
  AxisSide backward = AxisSide::kOccluded;  // the other side
  double forward_half_angle_deg = 45.0;     // 0..70
  double backward_half_angle_deg = 45.0;
};
inline constexpr int kMaxEdgeRays = 256;

// One ray's edge point, in the unstretched frame relative to the blob's centroid.
struct EdgePoint {
  double x = 0.0, y = 0.0;
  double sigma = 0.0;  // edge position noise (px): image noise over the edge's gradient
  int ray = 0;         // index of the ray (angle 2 pi ray / rays, image x towards y)
};

// The edge of one blob as sample_edge() found it.
struct EdgeSamples {
  std::array<EdgePoint, kMaxEdgeRays> points{};
  int count = 0;                    // rays that found the edge
  int rays = 0;                     // rays cast
  double x0_px = 0.0, y0_px = 0.0;  // the centroid the rays start from
  double contrast_dn = 0.0, noise_dn = 0.0;
  double ux = 1.0, uy = 0.0, stretch = 1.0;  // the radial direction and stretch undone
};

struct EdgeCentre {
  bool ok = false;
  double x_px = 0.0, y_px = 0.0;  // the ball image's centre (image pixels)
  double radius_px = 0.0;         // the fitted circle's radius (in the unstretched frame)
  int edge_points = 0;            // rays that found the edge
  int inliers = 0;                // edge points on the circle
  double rms_px = 0.0;            // inliers' radial residual RMS
  // The centre's covariance (image pixels^2): the fit's, from the inliers' residual
  // variance, widened for the rays being closer than a pixel along the rim (neighbouring
  // rays read the same pixels: about one independent edge sample per pixel of rim).
  Eigen::Matrix2d cov_px2 = Eigen::Matrix2d::Zero();
  bool checked_used = false;  // AxisSide::kChecked rays were used (they agreed)
};

// `noise_dn`: the image's noise sigma (BlobList::levels().noise_dn). `radial_x/_y`: unit
// direction from the image's principal point to the blob (any unit vector at the
// centre); `radial_stretch`: a whole ball's image extent along that direction over its
// extent across it (1: a circle). False (out untouched but count = 0): a faint blob or
// an empty image.
bool sample_edge(const ImageView& img, const Blob& blob, double noise_dn, double radial_x,
                 double radial_y, double radial_stretch, const EdgeCentreConfig& cfg,
                 EdgeSamples& out) noexcept;

// The robust circle fit of sampled edge points (cfg's rays, level and step are
// sample_edge()'s and are not used here).
EdgeCentre fit_edge_centre(const EdgeSamples& samples, const EdgeCentreConfig& cfg = {},
                           EdgeAxis axis = {}) noexcept;

// sample_edge() then fit_edge_centre().
EdgeCentre edge_centre(const ImageView& img, const Blob& blob, double noise_dn, double radial_x,
                       double radial_y, double radial_stretch, const EdgeCentreConfig& cfg = {},
                       EdgeAxis axis = {}) noexcept;

}  // namespace mocap::detect
