// Design: the wand balls' image centres over a whole recording, unbiased along the wand.
//
// A wand's rod enters its balls. Where it comes towards the camera it hides a notch of
// the ball's rim, and its blurred flank darkens the rim beside the notch by less than the
// edge fit can reject. Whatever remains moves each end ball's centre away from the rod:
// the wand is measured too long in every frame, which sets the rig's scale (and every
// camera's distance from camera 0) wrong, and no number of frames averages it out
// (docs/rig_calibration.md, "Partly hidden wand balls"). Leaving out the rim within a
// cut angle of the axis on the rod's side removes the bias but costs precision along the
// wand, the very direction that sets the scale: the wider the cut, the noisier.
//
// How wide the cut must be depends on the rod (its diameter over the ball's), on how the
// rod is mounted, on the blur and on the balls' sizes in the images: none of it is in
// the wand file. The default, kDefaultRodCutDeg, is a prior: a rod half the ball's
// diameter hides the rim within asin(0.5) = 30 degrees in a sharp image, and its blurred
// flank reaches about one edge width further (PSF and pixel, ~0.6 px: 5.7 degrees of
// rim on a ball 6 px in radius, 11 on one of 3 px). Smaller or blurrier balls, or a
// thicker rod, need more, and the recording says so: every
// end ball's edge is sampled once (detect::sample_edge) and fitted with each candidate
// cut (kRodCutsDeg); the widest is the reference. Per candidate, over all end-ball views:
//  - the mean shift of the centre from the reference, away from the rod: the bias the
//    narrower cut lets in (positive: the rod pushes the centre out), with its standard
//    error from the spread over the views;
//  - the centre's noise along the wand (the fits' own covariance, RMS over the views).
// When the default's shift exceeds kWidenSigmas standard errors (a thicker rod, a
// blurrier lens), the cut widens to the narrowest candidate whose shift lies within
// kKeepSigmas of its standard error. The cut never narrows below the default: a bias
// smaller than the default's is too small for one recording to measure.
//
// The outer side of an end ball (beyond the wand's ends: free, or a handle) is used when
// its own fit agrees (detect::AxisSide::kChecked). Every centre is finally moved from
// the silhouette's centre to the projection of the ball's centre (ball_centre_pixel):
// the perspective and lens offset is outwards in every frame, a few thousandths of a
// pixel that would otherwise also stretch the wand.
// Setup-time, offline code: allocates.
#pragma once

#include <array>
#include <cstddef>
#include <vector>

#include "camera/camera_model.h"
#include "detect/edge_centre.h"
#include "rigcal/bundle.h"

namespace mocap::rigcal {

inline constexpr std::array<double, 9> kRodCutsDeg = {20.0, 25.0, 30.0, 35.0, 40.0,
                                                      45.0, 50.0, 55.0, 60.0};
inline constexpr double kDefaultRodCutDeg = 35.0;
inline constexpr double kWidenSigmas = 3.0;
inline constexpr double kKeepSigmas = 2.0;

// Where a ball sits on the wand, which says on which side of it the rod runs.
enum class WandBallRole : unsigned char { kFirst, kMiddle, kLast };

// The choice of the rod-side cut and the figures behind it (report.yaml, wand_centres).
struct RodCutChoice {
  double cut_deg = kDefaultRodCutDeg;
  bool from_recording = false;  // chosen from the recording (else fixed by the options)
  int end_ball_views = 0;       // end-ball views with every candidate fitted
  double outer_rim_used = 0.0;  // fraction of end-ball views whose outer rim agreed (at cut_deg)
  // Per candidate (kRodCutsDeg): the mean shift away from the rod against the widest
  // cut, its standard error, and the centres' noise along the wand (px).
  std::array<double, kRodCutsDeg.size()> mean_shift_px{};
  std::array<double, kRodCutsDeg.size()> standard_error_px{};
  std::array<double, kRodCutsDeg.size()> along_sd_px{};
};

// The index of the cut the figures call for (the rule above); exposed for tests.
std::size_t choose_rod_cut(const RodCutChoice& figures);

// Collects the candidate centres of every wand ball of a recording, then writes the
// chosen ones into the recording's blobs.
class WandCentres {
 public:
  // cfg: the edge fit's configuration, the one the samples were taken with.
  explicit WandCentres(const detect::EdgeCentreConfig& cfg = {}) : cfg_(cfg) {}

  // One ball of a labelled wand in one image. blobs[frame][camera][slot] receives its
  // centre in apply(). axis: image direction from the wand's first ball to its last.
  // Returns false (nothing added) when the ball's edge could not be fitted: the slot
  // keeps what the caller put there. partly_hidden: the ball's blob is less round than a
  // whole ball's (its rim visibly cut); such views get a cut of their own.
  bool add(const detect::EdgeSamples& samples, const CameraModel& cam, WandBallRole role,
           const Vec2& axis, std::size_t frame, std::size_t camera, std::size_t slot,
           bool partly_hidden = false);

  // The choice over the views added (those partly hidden, or the others); fixed_cut_deg
  // > 0 forces that cut (the nearest candidate).
  RodCutChoice choose(double fixed_cut_deg, bool partly_hidden = false) const;

  // Writes every added ball's centre for its class's chosen cut (partly_hidden: that of
  // the partly hidden views; null: `choice` for all) and, when info is given (the same
  // shape as blobs), the edge fit's covariance of that centre (px^2).
  void apply(const RodCutChoice& choice, FrameBlobs& blobs, FrameCentreInfo* info = nullptr,
             const RodCutChoice* partly_hidden = nullptr) const;

 private:
  struct View {
    std::size_t frame = 0, camera = 0, slot = 0;
    bool end = false;
    bool partly_hidden = false;
    std::array<bool, kRodCutsDeg.size()> outer_used{};  // the outer rim agreed
    Vec2 away_from_rod = Vec2::Zero();
    std::array<Eigen::Matrix2d, kRodCutsDeg.size()> cov_px2{};
    std::array<Vec2, kRodCutsDeg.size()> centre_px{};
    std::array<bool, kRodCutsDeg.size()> ok{};
  };
  std::vector<View> views_;
  detect::EdgeCentreConfig cfg_{};
};

}  // namespace mocap::rigcal
