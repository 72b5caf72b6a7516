// The wand balls' centres over a recording (rigcal/wand_centres.h): the rule that
// chooses the rod-side cut, and WandCentres on end balls drawn by tests/detect/synth.h
// (not the simulator): with no rod the cut stays at its default and the outer rim is
// used; a thick rod whose blurred flank reaches past the default widens the cut, and the
// wider cut's centres are less biased than the default's; partly hidden balls get a cut
// of their own.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "detect/blob_detector.h"
#include "rigcal/wand_centres.h"
#include "tests/detect/synth.h"

namespace mocap::rigcal {
namespace {

constexpr std::size_t kCuts = kRodCutsDeg.size();

std::size_t index_of(double deg) {
  std::size_t j = 0;
  while (kRodCutsDeg[j] < deg) ++j;
  return j;
}

TEST(WandCentres, CutRule) {
  RodCutChoice f;
  f.standard_error_px.fill(0.001);
  f.standard_error_px[kCuts - 1] = 0.0;
  // Within 3 sigma at the default: the default, even where narrower cuts are unbiased.
  f.mean_shift_px[index_of(kDefaultRodCutDeg)] = 0.0029;
  EXPECT_EQ(kRodCutsDeg[choose_rod_cut(f)], kDefaultRodCutDeg);
  // Beyond: the narrowest wider cut within 2 sigma.
  f.mean_shift_px[index_of(35.0)] = 0.0035;
  f.mean_shift_px[index_of(40.0)] = 0.0025;
  f.mean_shift_px[index_of(45.0)] = 0.0019;
  EXPECT_EQ(kRodCutsDeg[choose_rod_cut(f)], 45.0);
  // A shift the other way counts as much.
  f.mean_shift_px[index_of(45.0)] = -0.0021;
  EXPECT_EQ(kRodCutsDeg[choose_rod_cut(f)], 50.0);
  // Nothing within: the reference (whose own shift is 0 by definition).
  for (std::size_t j = 0; j + 1 < kCuts; ++j) f.mean_shift_px[j] = 0.01;
  EXPECT_EQ(choose_rod_cut(f), kCuts - 1);
}

struct Scene {
  double radius_px, rod_width_px, blur_px;
};

struct Outcome {
  RodCutChoice choice;
  double chosen_outward_px = 0.0, default_outward_px = 0.0;
};

// Views of a recording: each ball's true centre, the direction away from its rod, and
// its slot in blobs (one frame per view).
struct Views {
  std::vector<Vec2> truth, away;
  FrameBlobs blobs;
};

// Adds n views of sc to wc (flagged partly_hidden as given).
void add_views(WandCentres& wc, Views& v, const Scene& sc, int n, std::uint32_t seed,
               bool partly_hidden = false) {
  detect::test::SynthParams p;
  p.width = 32;
  p.height = 32;
  p.background_dn = 20.0;
  p.noise_sigma_dn = 2.0;
  p.blur_sigma_px = sc.blur_px;
  CameraModel cam;  // a long lens looking at the ball: no perspective offset to speak of
  cam.width = p.width;
  cam.height = p.height;
  cam.fx = cam.fy = 1.0e6;
  cam.cx = cam.cy = 15.5;
  auto det = detect::BlobDetector::create(detect::DetectorConfig{}, p.width, p.height);
  ASSERT_TRUE(static_cast<bool>(det));
  detect::BlobList list = det->make_blob_list();
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> sub(-0.5, 0.5), angle(-M_PI, M_PI);
  for (int i = 0; i < n; ++i) {
    p.seed = seed + static_cast<std::uint32_t>(i);
    const double x = 15.5 + sub(rng), y = 15.5 + sub(rng), phi = angle(rng);
    const detect::test::SynthImage im =
        detect::test::ball_with_rod(p, x, y, sc.radius_px, 180.0, sc.rod_width_px, phi);
    det->detect(im.view, list);
    if (list.size() != 1) continue;
    detect::EdgeSamples samples;
    if (!detect::sample_edge(im.view, list[0], list.levels().noise_dn, 1.0, 0.0, 1.0, {}, samples))
      continue;
    // The rod leaves the ball at phi: the wand's axis (first ball -> last) points the
    // other way, and this is the last ball.
    const Vec2 axis(-std::cos(phi), -std::sin(phi));
    const std::size_t f = v.blobs.size();
    v.blobs.push_back({{Vec2(list[0].x_px, list[0].y_px)}});
    if (!wc.add(samples, cam, WandBallRole::kLast, axis, f, 0, 0, partly_hidden)) {
      v.blobs.pop_back();
      continue;
    }
    v.truth.emplace_back(x, y);
    v.away.push_back(axis);
  }
}

// Mean error of views [first, last) of blobs, outwards along the wand (px).
double outward_px(const Views& v, const FrameBlobs& blobs, std::size_t first, std::size_t last) {
  double sum = 0.0;
  for (std::size_t i = first; i < last; ++i) sum += (blobs[i][0][0] - v.truth[i]).dot(v.away[i]);
  return last > first ? sum / static_cast<double>(last - first) : 0.0;
}

// n views of a recording's last wand ball (the rod behind it, nothing beyond), at random
// sub-pixel positions and wand directions; returns the choice and the mean error of the
// chosen centres and of the default cut's, outwards along the wand (px).
Outcome run(const Scene& sc, int n, std::uint32_t seed) {
  WandCentres wc;
  Views v;
  add_views(wc, v, sc, n, seed);
  Outcome out;
  out.choice = wc.choose(0.0);
  FrameBlobs chosen = v.blobs, at_default = v.blobs;
  RodCutChoice fixed = out.choice;
  fixed.cut_deg = kDefaultRodCutDeg;
  wc.apply(out.choice, chosen);
  wc.apply(fixed, at_default);
  out.chosen_outward_px = outward_px(v, chosen, 0, v.truth.size());
  out.default_outward_px = outward_px(v, at_default, 0, v.truth.size());
  return out;
}

TEST(WandCentres, NoRodKeepsTheDefaultCutAndUsesTheOuterRim) {
  const Outcome o = run({4.0, 0.0, 0.5}, 150, 11u);
  EXPECT_GE(o.choice.end_ball_views, 140);
  EXPECT_TRUE(o.choice.from_recording);
  EXPECT_EQ(o.choice.cut_deg, kDefaultRodCutDeg);
  EXPECT_GT(o.choice.outer_rim_used, 0.8);
  EXPECT_LT(std::fabs(o.chosen_outward_px), 0.01);
  // Narrower cuts see more rim: less noise along the wand.
  EXPECT_LT(o.choice.along_sd_px[0], o.choice.along_sd_px[kCuts - 1]);
}

TEST(WandCentres, ThickBlurredRodWidensTheCut) {
  // A rod 0.9 x the ball's radius wide on a 3 px ball blurred by 1 px: the notch spans
  // +-27 degrees and its flank another ~20 degrees, past the default cut.
  const Outcome o = run({3.0, 2.7, 1.0}, 150, 23u);
  EXPECT_GT(o.choice.cut_deg, kDefaultRodCutDeg);
  EXPECT_GT(o.choice.mean_shift_px[index_of(kDefaultRodCutDeg)],
            kWidenSigmas * o.choice.standard_error_px[index_of(kDefaultRodCutDeg)]);
  EXPECT_LT(std::fabs(o.chosen_outward_px), 0.5 * std::fabs(o.default_outward_px));
}

// Whole balls (no rod to speak of) and partly hidden ones (a thick blurred rod) in one
// recording: each class gets its own cut, and the partly hidden balls' centres are less
// biased than with the whole balls' cut, which stays at the default.
TEST(WandCentres, PartlyHiddenViewsGetTheirOwnCut) {
  WandCentres wc;
  Views v;
  add_views(wc, v, {4.0, 0.0, 0.5}, 150, 31u, false);
  const std::size_t whole = v.truth.size();
  add_views(wc, v, {3.0, 2.7, 1.0}, 150, 37u, true);
  const RodCutChoice w = wc.choose(0.0, false), h = wc.choose(0.0, true);
  EXPECT_EQ(w.end_ball_views, static_cast<int>(whole));
  // (views with every candidate cut fitted: not all of the thick rod's)
  EXPECT_GT(h.end_ball_views, 50);
  EXPECT_LE(h.end_ball_views, static_cast<int>(v.truth.size() - whole));
  EXPECT_EQ(w.cut_deg, kDefaultRodCutDeg);
  EXPECT_GT(h.cut_deg, kDefaultRodCutDeg);
  FrameBlobs own = v.blobs, one = v.blobs;
  wc.apply(w, own, nullptr, &h);
  wc.apply(w, one);
  for (std::size_t i = 0; i < whole; ++i) EXPECT_EQ(own[i][0][0], one[i][0][0]);
  EXPECT_LT(std::fabs(outward_px(v, own, whole, v.truth.size())),
            0.5 * std::fabs(outward_px(v, one, whole, v.truth.size())));
}

TEST(WandCentres, FixedCutAndTooFewViews) {
  const Outcome few = run({4.0, 0.0, 0.5}, 20, 5u);
  EXPECT_FALSE(few.choice.from_recording);
  EXPECT_EQ(few.choice.cut_deg, kDefaultRodCutDeg);
  WandCentres empty;
  EXPECT_EQ(empty.choose(42.0).cut_deg, 40.0);  // the nearest candidate
  EXPECT_FALSE(empty.choose(42.0).from_recording);
  detect::EdgeSamples none;
  CameraModel cam;
  EXPECT_FALSE(empty.add(none, cam, WandBallRole::kFirst, Vec2(1.0, 0.0), 0, 0, 0));
  EXPECT_FALSE(empty.add(none, cam, WandBallRole::kFirst, Vec2::Zero(), 0, 0, 0));
}

}  // namespace
}  // namespace mocap::rigcal
