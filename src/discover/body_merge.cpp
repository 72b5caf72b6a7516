// Design: the merge of one body built twice (body_builder_detail.h, docs/discover.md):
// by constant relative poses where both are posed, else by the rigid alignment of >= 3
// markers checked against the frames where both are posed, else by markers that
// coincide in the world while both are posed.
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <utility>
#include <vector>

#include "discover/body_builder_detail.h"

namespace mocap::discover::detail {
namespace {

// The merge tolerances of a constant relative pose: one body seen twice keeps its
// relative pose within the pose noise of two fits, far below these.
constexpr double kSameRotationDeg = 1.0;
constexpr double kSameTranslationMm = 2.0;

// True when every relative pose in `rel` is T_ab within the tolerances above.
bool all_within(const std::vector<Iso3>& rel, const Iso3& T_ab) {
  for (const Iso3& T : rel) {
    if (Eigen::AngleAxisd(T.linear() * T_ab.linear().transpose()).angle() * kDegPerRad >
            kSameRotationDeg ||
        (T.translation() - T_ab.translation()).norm() > kSameTranslationMm)
      return false;
  }
  return true;
}

// T_world_A^-1 * T_world_B in every frame where both are posed.
std::vector<Iso3> relative_poses(const DiscoveredBody& a, const DiscoveredBody& b) {
  std::vector<Iso3> rel;
  for (std::size_t f = 0; f < a.found.size() && f < b.found.size(); ++f)
    if (a.found[f] && b.found[f]) rel.push_back(a.T_world_body[f].inverse() * b.T_world_body[f]);
  return rel;
}

// The marker of `markers` nearest to X (index, distance); index -1 when there is none.
std::pair<int, double> nearest_marker(const std::vector<Vec3>& markers, const Vec3& X) {
  std::pair<int, double> best{-1, 1e300};
  for (std::size_t k = 0; k < markers.size(); ++k) {
    const double d = (markers[k] - X).norm();
    if (d < best.second) best = {static_cast<int>(k), d};
  }
  return best;
}

// The same body built twice from clusters of different time windows (occlusions cut
// every track between them): B is A when A's target, identified among B's tracks (and
// B's among A's), keeps one constant pose relative to B (rotation within 1 deg,
// translation within 2 mm: kSameRotationDeg, kSameTranslationMm) over at least
// min_covisible_frames() frames in which A turned by min_body_turn_rad(A's radius). B's markers
// then join A's (or are left to the pool). Pose-based test (above); returns false when it cannot
// decide or says no.
bool same_by_poses(const Builder& A, const Builder& B, Iso3& T_ab) {
  Builder a = A, b = B;
  a.extend_poses(B.members);
  b.extend_poses(A.members);
  std::vector<int> fs;
  for (std::size_t f = 0; f < a.frames(); ++f)
    if (a.body.found[f] && b.body.found[f]) fs.push_back(static_cast<int>(f));
  if (static_cast<int>(fs.size()) < A.opt.min_covisible_frames()) return false;
  if (a.rotation_range_deg(fs) / kDegPerRad < A.opt.min_body_turn_rad(a.lever_mm(Vec3::Zero())))
    return false;
  const std::vector<Iso3> rel = relative_poses(a.body, b.body);
  T_ab = rel[rel.size() / 2];
  return all_within(rel, T_ab);
}

// Shape-based test (bodies mostly posed in different time windows):
// at least 3 markers of B align with distinct markers of A by one rigid motion, every
// residual within 4 fit tolerances, and no marker of B lands where A has none nearby
// but within one marker diameter (an inconsistent overlap); in every frame where both
// are posed, their relative pose must be that alignment (within 1 deg and 2 mm).
bool same_by_shape(const Builder& A, const Builder& B, Iso3& T_ab) {
  const auto& ma = A.body.markers_body;
  const auto& mb = B.body.markers_body;
  const double tol = 4.0 * A.opt.body_fit_tolerance_mm();
  int best = 0;
  double best_rms = 1e300;
  const std::size_t na = ma.size(), nb = mb.size();
  for (std::size_t i = 0; i < nb; ++i)
    for (std::size_t j = i + 1; j < nb; ++j)
      for (std::size_t k = j + 1; k < nb; ++k)
        for (std::size_t p = 0; p < na; ++p)
          for (std::size_t q = 0; q < na; ++q)
            for (std::size_t r = 0; r < na; ++r) {
              if (p == q || q == r || p == r) continue;
              auto close = [&](std::size_t x, std::size_t y, std::size_t u, std::size_t v) {
                return std::abs((mb[x] - mb[y]).norm() - (ma[u] - ma[v]).norm()) <= tol;
              };
              if (!close(i, j, p, q) || !close(j, k, q, r) || !close(i, k, p, r)) continue;
              Eigen::Matrix3d S, D;
              S << mb[i], mb[j], mb[k];
              D << ma[p], ma[q], ma[r];
              Iso3 T;
              T.matrix() = Eigen::umeyama(S, D, false);
              int matched = 0;
              double sum2 = 0.0;
              bool conflict = false;
              for (std::size_t m = 0; m < nb; ++m) {
                const double d_min = nearest_marker(ma, T * mb[m]).second;
                if (d_min <= tol) {
                  ++matched;
                  sum2 += d_min * d_min;
                } else if (d_min < A.opt.marker_diameter_mm) {
                  conflict = true;
                }
              }
              if (conflict || matched < 3) continue;
              const double rms = std::sqrt(sum2 / matched);
              if (matched > best || (matched == best && rms < best_rms)) {
                best = matched;
                best_rms = rms;
                T_ab = T;
              }
            }
  if (best < 3) return false;
  // Frames where both are posed must show that same relative pose (else: two bodies).
  return all_within(relative_poses(A.body, B.body), T_ab);
}

// Coincidence test (bodies posed together, e.g. a still torso whose tracks were cut
// into fragments by the arm passing in front of it): over at least min_covisible_frames()
// frames where both are posed, their relative pose is constant (1 deg, 2 mm), and at
// least 2 markers of B then lie on distinct markers of A (within 4 fit tolerances), none
// half-way (within one marker diameter but not on a marker). Two distinct bodies cannot
// hold markers at the same place at the same time, so this needs no motion.
bool same_by_coincidence(const Builder& A, const Builder& B, Iso3& T_ab) {
  const std::vector<Iso3> rel = relative_poses(A.body, B.body);
  if (static_cast<int>(rel.size()) < A.opt.min_covisible_frames()) return false;
  T_ab = rel[rel.size() / 2];
  if (!all_within(rel, T_ab)) return false;
  const double tol = 4.0 * A.opt.body_fit_tolerance_mm();
  std::vector<char> taken(A.body.markers_body.size(), 0);
  int on = 0;
  for (const Vec3& m : B.body.markers_body) {
    const auto [nearest, d_min] = nearest_marker(A.body.markers_body, T_ab * m);
    if (nearest >= 0 && d_min <= tol && !taken[static_cast<std::size_t>(nearest)]) {
      taken[static_cast<std::size_t>(nearest)] = 1;
      ++on;
    } else if (d_min < A.opt.marker_diameter_mm) {
      return false;
    }
  }
  return on >= 2;
}

}  // namespace

bool merge_if_same(Builder& A, const Builder& B, std::vector<int>& released) {
  Iso3 T_ab = Iso3::Identity();
  if (!same_by_poses(A, B, T_ab) && !same_by_shape(A, B, T_ab) && !same_by_coincidence(A, B, T_ab))
    return false;
  for (std::size_t m = 0; m < B.body.markers_body.size(); ++m) {
    const Vec3 X_a = T_ab * B.body.markers_body[m];
    const auto [nearest, d_min] = nearest_marker(A.body.markers_body, X_a);
    const auto& tracks_m = B.body.marker_tracks[m];
    bool coexists = false;
    if (nearest >= 0)
      for (int ti : tracks_m) coexists = coexists || A.overlaps_marker(ti, nearest);
    int target = -1;
    if (d_min <= 0.25 * A.opt.marker_diameter_mm && !coexists)
      target = nearest;
    else if (d_min >= A.opt.marker_diameter_mm)
      target = static_cast<int>(A.body.markers_body.size());
    for (int ti : tracks_m) {
      if (target < 0) {
        released.push_back(ti);
        continue;
      }
      A.place(ti, target, X_a);
    }
  }
  A.compute_poses();
  return true;
}

}  // namespace mocap::discover::detail
