// Design: see limb_layout.h. Random layouts are drawn (azimuths spread evenly over the
// allowed arc with jitter, heights uniform along the limb, gaps 3..5 mm) and the first
// that passes every rule is taken; the triangle test is a sorted-sides pre-test, then
// Umeyama (Eigen) over the six correspondences.
#include "sim/limb_layout.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <string>

#include "core/units.h"
#include "sim/scene_build.h"
#include "sim/sim_rng.h"

namespace mocap::sim {
namespace {

// A triangle of balls: its corners and its sorted side lengths (a cheap pre-test: two
// triangles whose sorted sides differ by more than 2 sqrt(3) x the fit RMS cannot fit).
struct Triangle {
  Eigen::Matrix3d corners;  // columns
  std::array<double, 3> sides;
};

Triangle triangle(const Vec3& a, const Vec3& b, const Vec3& c) {
  Triangle t;
  t.corners << a, b, c;
  t.sides = {(a - b).norm(), (b - c).norm(), (a - c).norm()};
  std::sort(t.sides.begin(), t.sides.end());
  return t;
}

// Whether y fits x within rms_mm under some correspondence and rigid motion (with
// `self`, x and y are one triangle and the identity correspondence does not count: a
// nearly isosceles triangle fits itself turned over).
bool triangles_match(const Triangle& x, const Triangle& y, double rms_mm, bool self = false) {
  for (std::size_t i = 0; i < 3; ++i) {
    if (std::abs(x.sides[i] - y.sides[i]) > 2.0 * std::sqrt(3.0) * rms_mm) return false;
  }
  std::array<int, 3> perm = {0, 1, 2};
  do {
    if (self && perm == std::array<int, 3>{0, 1, 2}) continue;
    Eigen::Matrix3d src;
    for (int k = 0; k < 3; ++k) src.col(k) = y.corners.col(perm[static_cast<std::size_t>(k)]);
    const Eigen::Matrix4d T = Eigen::umeyama(src, x.corners, false);
    const Eigen::Matrix3d moved =
        (T.topLeftCorner<3, 3>() * src).colwise() + T.topRightCorner<3, 1>();
    if (std::sqrt((moved - x.corners).squaredNorm() / 3.0) < rms_mm) return true;
  } while (std::next_permutation(perm.begin(), perm.end()));
  return false;
}

// The triangles of a point set (world, reference pose).
std::vector<Triangle> triangles_of(const std::vector<Vec3>& p) {
  std::vector<Triangle> t;
  for (std::size_t i = 0; i < p.size(); ++i)
    for (std::size_t j = i + 1; j < p.size(); ++j)
      for (std::size_t k = j + 1; k < p.size(); ++k) t.push_back(triangle(p[i], p[j], p[k]));
  return t;
}

// Distance from p to the segment a-b.
double segment_distance(const Vec3& p, const Vec3& a, const Vec3& b) {
  const Vec3 ab = b - a;
  const double s = std::clamp((p - a).dot(ab) / ab.squaredNorm(), 0.0, 1.0);
  return (p - (a + s * ab)).norm();
}

// A ball clears every limb of the robot but its own main limb by rules.clearance_mm.
bool ball_clears(const Vec3& c, const std::vector<LimbBody>& all, const LimbBody& own,
                 const LayoutRules& rules) {
  for (const LimbBody& b : all) {
    for (std::size_t i = 0; i < b.limbs.size(); ++i) {
      if (&b == &own && i == 0) continue;
      const LimbCapsule& l = b.limbs[i];
      if (segment_distance(c, l.a, l.b) < l.radius_mm + rules.ball_radius_mm + rules.clearance_mm)
        return false;
    }
  }
  return true;
}

// A layout for one body that passes the design rules against the targets placed so
// far (their triangles in `placed`). Deterministic: the rng is the robot's.
Expected<std::vector<Mount>> search_layout(const std::vector<LimbBody>& all, const LimbBody& body,
                                           const LayoutRules& rules, Rng& rng,
                                           const std::vector<Triangle>& placed) {
  const LimbCapsule& main = body.limbs[0];
  Vec3 d, front, side;
  limb_azimuth_frame(main.a, main.b, d, front, side);
  const double len = (main.b - main.a).norm();
  const int n = body.markers;
  for (int attempt = 0; attempt < 1000000; ++attempt) {
    std::vector<Mount> mounts;
    std::vector<Vec3> centers;
    const double span = body.phi_hi_deg - body.phi_lo_deg;
    const double phase = rng.uniform(0.0, 1.0);
    for (int k = 0; k < n; ++k) {
      // Azimuths spread all around the allowed arc, heights spread along the limb.
      const double u = (k + phase + rng.uniform(-0.3, 0.3)) / n;
      const double phi = body.phi_lo_deg + span * (u - std::floor(u));
      const double s = body.s_lo + (body.s_hi - body.s_lo) * rng.uniform(0.0, 1.0);
      const double gap = 3.0 + std::floor(rng.uniform(0.0, 3.0));
      const Vec3 dir = std::sin(phi * kRadPerDeg) * side + std::cos(phi * kRadPerDeg) * front;
      const Vec3 axis_pt = main.a + s * len * d;
      const Vec3 center = axis_pt + dir * (main.radius_mm + gap + rules.ball_radius_mm);
      mounts.push_back({center, axis_pt + dir * (main.radius_mm - 3.0)});
      centers.push_back(center);
    }
    bool ok = true;
    for (int k = 0; k < n && ok; ++k)
      ok = ball_clears(centers[static_cast<std::size_t>(k)], all, body, rules);
    if (!ok) continue;
    std::vector<double> dist;
    for (int i = 0; i < n && ok; ++i) {
      for (int j = i + 1; j < n && ok; ++j) {
        const double dij =
            (centers[static_cast<std::size_t>(i)] - centers[static_cast<std::size_t>(j)]).norm();
        ok = dij >= rules.min_ball_gap_mm;
        dist.push_back(dij);
      }
    }
    if (!ok) continue;
    std::sort(dist.begin(), dist.end());
    for (std::size_t i = 1; i < dist.size() && ok; ++i)
      ok = dist[i] - dist[i - 1] >= rules.min_distance_step_mm;
    if (!ok) continue;
    const auto own = triangles_of(centers);
    for (std::size_t i = 0; i < own.size() && ok; ++i) {
      for (std::size_t j = i; j < own.size() && ok; ++j)
        ok = !triangles_match(own[i], own[j], rules.self_fit_mm, i == j);
      for (std::size_t j = 0; j < placed.size() && ok; ++j)
        ok = !triangles_match(own[i], placed[j], rules.cross_fit_mm);
    }
    if (ok) return mounts;
  }
  return make_error("simulate", "scene",
                    std::string("no marker layout found for '") + body.name + "'");
}

}  // namespace

Expected<std::vector<std::vector<Mount>>> search_limb_layout(const std::vector<LimbBody>& bodies,
                                                             const LayoutRules& rules) {
  Rng rng(rules.seed);
  std::vector<Triangle> placed;
  std::vector<std::vector<Mount>> layout;
  for (const LimbBody& body : bodies) {
    auto mounts = search_layout(bodies, body, rules, rng, placed);
    if (!mounts) return mounts.error();
    std::vector<Vec3> centers;
    for (const Mount& m : *mounts) centers.push_back(m.center);
    for (const auto& t : triangles_of(centers)) placed.push_back(t);
    layout.push_back(std::move(mounts).value());
  }
  return layout;
}

}  // namespace mocap::sim
