// Design: see wand_centres.h.
#include "rigcal/wand_centres.h"

#include <algorithm>
#include <cmath>

namespace mocap::rigcal {
namespace {

constexpr std::size_t kCuts = kRodCutsDeg.size();
constexpr std::size_t kReference = kCuts - 1;  // the widest cut
constexpr std::size_t kDefault = [] {
  std::size_t j = 0;
  while (kRodCutsDeg[j] < kDefaultRodCutDeg) ++j;
  return j;
}();
static_assert(kRodCutsDeg[kDefault] == kDefaultRodCutDeg);
// Fewer end-ball views than this: too few to tell a bias; the cut stays at its default.
constexpr int kMinViewsToChoose = 50;

// The candidate nearest to a cut (degrees).
std::size_t nearest_cut(double deg) {
  std::size_t best = 0;
  for (std::size_t j = 1; j < kCuts; ++j)
    if (std::fabs(kRodCutsDeg[j] - deg) < std::fabs(kRodCutsDeg[best] - deg)) best = j;
  return best;
}

}  // namespace

std::size_t choose_rod_cut(const RodCutChoice& f) {
  auto within = [&](std::size_t j, double sigmas) {
    return std::fabs(f.mean_shift_px[j]) <= sigmas * f.standard_error_px[j];
  };
  std::size_t j = kDefault;
  if (within(j, kWidenSigmas)) return j;
  while (j < kReference && !within(j, kKeepSigmas)) ++j;
  return j;
}

bool WandCentres::add(const detect::EdgeSamples& samples, const CameraModel& cam, WandBallRole role,
                      const Vec2& axis, std::size_t frame, std::size_t camera, std::size_t slot,
                      bool partly_hidden) {
  const double n = axis.norm();
  if (!(n > 0.0)) return false;
  const Vec2 u = axis / n;
  detect::EdgeAxis ax{u.x(), u.y()};
  View v;
  v.frame = frame;
  v.camera = camera;
  v.slot = slot;
  v.end = role != WandBallRole::kMiddle;
  v.partly_hidden = partly_hidden;
  if (role == WandBallRole::kFirst) {  // the rod runs forward, the outside is behind
    ax.backward = detect::AxisSide::kChecked;
    v.away_from_rod = -u;
  } else if (role == WandBallRole::kLast) {
    ax.forward = detect::AxisSide::kChecked;
    v.away_from_rod = u;
  }
  bool any = false;
  for (std::size_t j = 0; j < kCuts; ++j) {
    // The rod's side(s) take the candidate cut; an outer side keeps its default arc.
    if (ax.forward == detect::AxisSide::kOccluded) ax.forward_half_angle_deg = kRodCutsDeg[j];
    if (ax.backward == detect::AxisSide::kOccluded) ax.backward_half_angle_deg = kRodCutsDeg[j];
    const detect::EdgeCentre e = detect::fit_edge_centre(samples, cfg_, ax);
    if (!e.ok) continue;
    Vec2 c;
    if (!ball_centre_pixel(cam, Vec2(e.x_px, e.y_px), e.radius_px, c)) c = Vec2(e.x_px, e.y_px);
    v.centre_px[j] = c;
    v.ok[j] = true;
    v.cov_px2[j] = e.cov_px2;
    v.outer_used[j] = e.checked_used;
    any = true;
  }
  if (!any) return false;
  views_.push_back(v);
  return true;
}

RodCutChoice WandCentres::choose(double fixed_cut_deg, bool partly_hidden) const {
  RodCutChoice out;
  std::array<double, kCuts> sum{}, sum_sq{}, sum_var{};
  std::array<int, kCuts> outer{};
  for (const View& v : views_) {
    if (!v.end || v.partly_hidden != partly_hidden ||
        std::find(v.ok.begin(), v.ok.end(), false) != v.ok.end())
      continue;
    ++out.end_ball_views;
    for (std::size_t j = 0; j < kCuts; ++j) {
      const double s = (v.centre_px[j] - v.centre_px[kReference]).dot(v.away_from_rod);
      sum[j] += s;
      sum_sq[j] += s * s;
      sum_var[j] += v.away_from_rod.dot(v.cov_px2[j] * v.away_from_rod);
      outer[j] += v.outer_used[j] ? 1 : 0;
    }
  }
  const double n = out.end_ball_views;
  // The outer rim's share at the cut finally chosen.
  auto finish = [&](std::size_t j) {
    out.cut_deg = kRodCutsDeg[j];
    if (n > 0) out.outer_rim_used = outer[j] / n;
    return out;
  };
  for (std::size_t j = 0; n > 1 && j < kCuts; ++j) {
    out.mean_shift_px[j] = sum[j] / n;
    const double var = std::max(sum_sq[j] / n - out.mean_shift_px[j] * out.mean_shift_px[j], 0.0);
    out.standard_error_px[j] = std::sqrt(var / (n - 1));
    out.along_sd_px[j] = std::sqrt(sum_var[j] / n);
  }
  if (fixed_cut_deg > 0.0) return finish(nearest_cut(fixed_cut_deg));
  if (out.end_ball_views < kMinViewsToChoose) return finish(kDefault);
  out.from_recording = true;
  return finish(choose_rod_cut(out));
}

void WandCentres::apply(const RodCutChoice& choice, FrameBlobs& blobs, FrameCentreInfo* info,
                        const RodCutChoice* partly_hidden) const {
  const std::size_t chosen_whole = nearest_cut(choice.cut_deg);
  const std::size_t chosen_hidden = nearest_cut((partly_hidden ? *partly_hidden : choice).cut_deg);
  for (const View& v : views_) {
    const std::size_t chosen = v.partly_hidden ? chosen_hidden : chosen_whole;
    // The chosen cut's centre, else the nearest wider one that fitted, else narrower.
    std::size_t j = chosen;
    while (j < kCuts && !v.ok[j]) ++j;
    if (j == kCuts) {
      j = chosen;
      while (j > 0 && !v.ok[j]) --j;
    }
    if (!v.ok[j]) continue;
    blobs[v.frame][v.camera][v.slot] = v.centre_px[j];
    if (info) (*info)[v.frame][v.camera][v.slot].cov_px2 = v.cov_px2[j];
  }
}

}  // namespace mocap::rigcal
