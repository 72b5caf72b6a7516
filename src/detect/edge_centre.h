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
// `axis_half_angle_deg` of either direction of that axis are not used at all: the rim
// there may be hidden by an amount too small to reject (a thin rod's blurred flank), and
// whatever bias it leaves points along the axis. The two remaining arcs are symmetric
// about the axis, so the fitted radius cannot trade against the centre's position along
// it. 45 degrees leaves out the rim a rod up to 0.7 x the ball's radius hides in a sharp
// image, or up to ~0.4 x when the blur spans 20 degrees of the rim (a ball 3 px in
// radius): a wand seen from 2-3 m.
// Not ok (use the centroid): a faint blob, too few edge points, or too few inliers.
// No allocation (fixed arrays); setup/offline code (the rig calibration), not the
// tracker's hot path.
#pragma once

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
  double axis_half_angle_deg = 45.0;  // rays left out on both sides of an occluder axis (EdgeAxis)
};

// An occluder axis in the image (any length; zero: none).
struct EdgeAxis {
  double x = 0.0, y = 0.0;
};
inline constexpr int kMaxEdgeRays = 256;

struct EdgeCentre {
  bool ok = false;
  double x_px = 0.0, y_px = 0.0;  // the ball image's centre (image pixels)
  double radius_px = 0.0;         // the fitted circle's radius (in the unstretched frame)
  int edge_points = 0;            // rays that found the edge
  int inliers = 0;                // edge points on the circle
  double rms_px = 0.0;            // inliers' radial residual RMS
};

// `noise_dn`: the image's noise sigma (BlobList::levels().noise_dn). `radial_x/_y`: unit
// direction from the image's principal point to the blob (any unit vector at the
// centre); `radial_stretch`: a whole ball's image extent along that direction over its
// extent across it (1: a circle).
EdgeCentre edge_centre(const ImageView& img, const Blob& blob, double noise_dn, double radial_x,
                       double radial_y, double radial_stretch, const EdgeCentreConfig& cfg = {},
                       EdgeAxis axis = {}) noexcept;

}  // namespace mocap::detect
