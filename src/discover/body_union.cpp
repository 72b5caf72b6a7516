// Design: see body_union.h.
#include "discover/body_union.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>

namespace mocap::discover {
namespace {

// RMS distance of the markers from their centroid.
double radius_mm(const DiscoveredBody& b) {
  if (b.markers_body.empty()) return 0.0;
  Vec3 c = Vec3::Zero();
  for (const Vec3& m : b.markers_body) c += m;
  c /= static_cast<double>(b.markers_body.size());
  double r2 = 0.0;
  for (const Vec3& m : b.markers_body) r2 += (m - c).squaredNorm();
  return std::sqrt(r2 / static_cast<double>(b.markers_body.size()));
}

// The two joints (parent frame) share one centre: ball centres within `tol`; hinge axes
// parallel within tol / radius and each point within `tol` of the other's axis line.
bool same_centre(const JointEdge& x, const JointEdge& y, double tol, double radius) {
  if (x.type != y.type) return false;
  if (x.type == JointType::kBall) return (x.center_parent - y.center_parent).norm() <= tol;
  const double angle = std::acos(std::min(1.0, std::abs(x.axis_parent.dot(y.axis_parent))));
  const Vec3 v = y.center_parent - x.center_parent;
  return angle <= tol / std::max(radius, 1e-9) &&
         (v - v.dot(x.axis_parent) * x.axis_parent).norm() <= tol;
}

}  // namespace

bool constant_relative_pose(const DiscoveredBody& A, const DiscoveredBody& B,
                            const DiscoverOptions& opt, Iso3& T_ab) {
  std::vector<Iso3> rel;
  for (std::size_t f = 0; f < A.found.size() && f < B.found.size(); ++f)
    if (A.found[f] && B.found[f]) rel.push_back(A.T_world_body[f].inverse() * B.T_world_body[f]);
  if (static_cast<int>(rel.size()) < opt.min_covisible_frames()) return false;
  // Reference: the per-element median (then re-orthonormalised) of the relative poses.
  Mat3 R = Mat3::Zero();
  Vec3 t = Vec3::Zero();
  std::vector<double> v(rel.size());
  for (int i = 0; i < 3; ++i) {
    for (std::size_t k = 0; k < rel.size(); ++k) v[k] = rel[k].translation()[i];
    std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2), v.end());
    t[i] = v[v.size() / 2];
    for (int j = 0; j < 3; ++j) {
      for (std::size_t k = 0; k < rel.size(); ++k) v[k] = rel[k].linear()(i, j);
      std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2), v.end());
      R(i, j) = v[v.size() / 2];
    }
  }
  const Eigen::Quaterniond q(R);
  T_ab = Iso3::Identity();
  T_ab.linear() = q.normalized().toRotationMatrix();
  T_ab.translation() = t;
  const double tol = 6.0 * std::sqrt(2.0) * opt.body_fit_tolerance_mm();
  const double max_rad = tol / std::max(std::min(radius_mm(A), radius_mm(B)), 1e-9);
  int off = 0;
  for (const Iso3& T : rel) {
    const double angle = Eigen::AngleAxisd(T.linear() * T_ab.linear().transpose()).angle();
    off += angle > max_rad || (T.translation() - T_ab.translation()).norm() > tol ? 1 : 0;
  }
  return off * 20 <= static_cast<int>(rel.size());
}

std::vector<std::pair<int, int>> find_split_bodies(const std::vector<DiscoveredBody>& bodies,
                                                   const TopologyResult& topo,
                                                   const DiscoverOptions& opt) {
  std::vector<std::pair<int, int>> pairs;
  std::vector<char> used(bodies.size(), 0);
  const double tol = 4.0 * opt.body_fit_tolerance_mm();
  const int n = static_cast<int>(bodies.size());
  // The parent of a: its tree parent if it has one (else every other body is tried).
  std::vector<int> parent(bodies.size(), -1);
  for (const JointEdge& e : topo.joints) parent[static_cast<std::size_t>(e.child)] = e.parent;
  for (int a = 0; a < n; ++a) {
    for (int b = a + 1; b < n; ++b) {
      if (used[static_cast<std::size_t>(a)] || used[static_cast<std::size_t>(b)]) continue;
      const DiscoveredBody& A = bodies[static_cast<std::size_t>(a)];
      const DiscoveredBody& B = bodies[static_cast<std::size_t>(b)];
      Iso3 T_ab;
      if (!constant_relative_pose(A, B, opt, T_ab)) continue;
      // One parent holding both at one joint centre: the tree's parent of either first.
      std::vector<int> parents;
      for (int p : {parent[static_cast<std::size_t>(a)], parent[static_cast<std::size_t>(b)]})
        if (p >= 0 && p != a && p != b) parents.push_back(p);
      for (int p = 0; p < n; ++p)
        if (p != a && p != b) parents.push_back(p);
      for (int p : parents) {
        const DiscoveredBody& P = bodies[static_cast<std::size_t>(p)];
        JointEdge x, y;
        if (!joint_candidate(P, A, opt, x) || !joint_candidate(P, B, opt, y) ||
            !same_centre(x, y, tol, radius_mm(P)))
          continue;
        const bool a_first = A.markers_body.size() >= B.markers_body.size();
        pairs.emplace_back(a_first ? a : b, a_first ? b : a);
        used[static_cast<std::size_t>(a)] = used[static_cast<std::size_t>(b)] = 1;
        break;
      }
    }
  }
  return pairs;
}

std::vector<DiscoveredBody> merge_bodies(std::vector<DiscoveredBody> bodies,
                                         const std::vector<std::pair<int, int>>& pairs,
                                         const DiscoverOptions& opt) {
  std::vector<char> removed(bodies.size(), 0);
  for (const auto& [a, b] : pairs) {
    DiscoveredBody& A = bodies[static_cast<std::size_t>(a)];
    const DiscoveredBody& B = bodies[static_cast<std::size_t>(b)];
    Iso3 T_ab;
    if (!constant_relative_pose(A, B, opt, T_ab)) continue;
    for (std::size_t m = 0; m < B.markers_body.size(); ++m) {
      const Vec3 X = T_ab * B.markers_body[m];
      std::size_t nearest = A.markers_body.size();
      double d_min = 1e300;
      for (std::size_t k = 0; k < A.markers_body.size(); ++k) {
        const double d = (A.markers_body[k] - X).norm();
        if (d < d_min) {
          d_min = d;
          nearest = k;
        }
      }
      if (nearest < A.markers_body.size() && d_min <= 0.25 * opt.marker_diameter_mm) {
        auto& tr = A.marker_tracks[nearest];
        tr.insert(tr.end(), B.marker_tracks[m].begin(), B.marker_tracks[m].end());
      } else if (d_min >= opt.marker_diameter_mm) {  // in between: left out (never a guess)
        A.markers_body.push_back(X);
        A.marker_tracks.push_back(B.marker_tracks[m]);
      }
    }
    for (std::size_t f = 0; f < A.found.size() && f < B.found.size(); ++f) {
      if (A.found[f] || !B.found[f]) continue;
      A.found[f] = 1;
      A.T_world_body[f] = B.T_world_body[f] * T_ab.inverse();
    }
    removed[static_cast<std::size_t>(b)] = 1;
    // Origin back at the markers' centroid (docs/discover.md, body frames).
    Vec3 c = Vec3::Zero();
    for (const Vec3& m : A.markers_body) c += m;
    c /= static_cast<double>(A.markers_body.size());
    for (Vec3& m : A.markers_body) m -= c;
    for (Iso3& T : A.T_world_body) T = T * Eigen::Translation3d(c);
  }
  std::vector<DiscoveredBody> out;
  for (std::size_t i = 0; i < bodies.size(); ++i)
    if (!removed[i]) out.push_back(std::move(bodies[i]));
  return out;
}

}  // namespace mocap::discover
