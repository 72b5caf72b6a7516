// Design: internal to body_builder.cpp and body_merge.cpp: the per-body builder state
// (placed tracks, markers, per-frame poses) and its operations (pose fits, placement
// tests, identification of occlusion gaps, refinement), and the merge of one body built
// twice from clusters of different time windows. Not part of the module's interface.
#pragma once

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <vector>

#include "core/median.h"
#include "core/units.h"
#include "discover/body_builder.h"
#include "identify/identifier.h"

namespace mocap::discover::detail {

inline constexpr double kDegPerRad = 57.29577951308232;

struct Builder {
  const std::vector<PointTrack>& tracks;
  const std::vector<char>& moving;
  const DiscoverOptions& opt;
  DiscoveredBody body;
  std::vector<int> members;  // tracks placed in this body
  std::vector<int> member_marker;

  std::size_t frames() const { return moving.size(); }

  // Pose of frame f from the placed tracks seen there; false with fewer than 3 agreeing.
  bool fit_pose(int f, Iso3& T) const {
    std::vector<Vec3> src, dst;
    for (std::size_t i = 0; i < members.size(); ++i) {
      const PointTrack& t = tracks[static_cast<std::size_t>(members[i])];
      if (!t.has(f)) continue;
      src.push_back(body.markers_body[static_cast<std::size_t>(member_marker[i])]);
      dst.push_back(t.at(f));
    }
    const double drop_mm = 5.0 * opt.body_fit_tolerance_mm();
    while (src.size() >= 3) {
      Eigen::Matrix3Xd S(3, static_cast<Eigen::Index>(src.size())), D(3, S.cols());
      for (std::size_t i = 0; i < src.size(); ++i) {
        S.col(static_cast<Eigen::Index>(i)) = src[i];
        D.col(static_cast<Eigen::Index>(i)) = dst[i];
      }
      T.matrix() = Eigen::umeyama(S, D, false);
      std::size_t worst = 0;
      double worst_mm = -1.0;
      for (std::size_t i = 0; i < src.size(); ++i) {
        const double r = (T * src[i] - dst[i]).norm();
        if (r > worst_mm) {
          worst_mm = r;
          worst = i;
        }
      }
      if (worst_mm <= drop_mm) return true;
      if (src.size() == 3) return false;
      src.erase(src.begin() + static_cast<std::ptrdiff_t>(worst));
      dst.erase(dst.begin() + static_cast<std::ptrdiff_t>(worst));
    }
    return false;
  }

  void compute_poses() {
    body.found.assign(frames(), 0);
    body.T_world_body.assign(frames(), Iso3::Identity());
    for (std::size_t f = 0; f < frames(); ++f)
      body.found[f] = fit_pose(static_cast<int>(f), body.T_world_body[f]) ? 1 : 0;
  }

  // Largest rotation between two of the poses of `fs` (two-pass diameter estimate), deg.
  double rotation_range_deg(const std::vector<int>& fs) const {
    auto farthest = [&](const Mat3& R_ref, double& angle) {
      int at = fs.front();
      angle = 0.0;
      for (int f : fs) {
        const double a = Eigen::AngleAxisd(R_ref.transpose() *
                                           body.T_world_body[static_cast<std::size_t>(f)].linear())
                             .angle();
        if (a > angle) {
          angle = a;
          at = f;
        }
      }
      return at;
    };
    double a = 0.0;
    const int f1 = farthest(body.T_world_body[static_cast<std::size_t>(fs.front())].linear(), a);
    farthest(body.T_world_body[static_cast<std::size_t>(f1)].linear(), a);
    return a * kDegPerRad;
  }

  // The lever of a body-frame position for the turn test: its distance from the markers'
  // centroid, at least the markers' RMS radius (the extent over which the body's
  // orientation is measured).
  double lever_mm(const Vec3& p_body) const {
    const auto& m = body.markers_body;
    if (m.empty()) return 1e-9;
    Vec3 c = Vec3::Zero();
    for (const Vec3& x : m) c += x;
    c /= static_cast<double>(m.size());
    double r2 = 0.0;
    for (const Vec3& x : m) r2 += (x - c).squaredNorm();
    return std::max((p_body - c).norm(), std::sqrt(r2 / static_cast<double>(m.size())));
  }

  // Body-frame position of track ti when it fits rigidly and informatively.
  bool fits(int ti, Vec3& mean_body) const {
    const PointTrack& t = tracks[static_cast<std::size_t>(ti)];
    std::vector<int> fs;
    std::vector<Vec3> y;
    for (int f = t.first; f <= t.last(); ++f) {
      if (!t.has(f) || !body.found[static_cast<std::size_t>(f)]) continue;
      fs.push_back(f);
      y.push_back(body.T_world_body[static_cast<std::size_t>(f)].inverse() * t.at(f));
    }
    if (static_cast<int>(fs.size()) < opt.min_placement_frames()) return false;
    mean_body = Vec3::Zero();
    for (const Vec3& v : y) mean_body += v;
    mean_body /= static_cast<double>(y.size());
    const double tol = opt.body_fit_tolerance_mm();
    double sum2 = 0.0;
    int far = 0;
    for (const Vec3& v : y) {
      const double r = (v - mean_body).norm();
      sum2 += r * r;
      far += r > 4.0 * tol ? 1 : 0;
    }
    if (std::sqrt(sum2 / static_cast<double>(y.size())) > tol ||
        far * 20 > static_cast<int>(y.size()))
      return false;
    if (rotation_range_deg(fs) / kDegPerRad >= opt.min_body_turn_rad(lever_mm(mean_body)))
      return true;
    // A still body: informative only when the point and the body stayed put while the scene moved.
    int moving_frames = 0;
    double spread = 0.0;
    const Vec3 p0 = t.at(fs.front());
    for (int f : fs) {
      moving_frames += moving[static_cast<std::size_t>(f)] != 0 ? 1 : 0;
      spread = std::max(spread, (t.at(f) - p0).norm());
    }
    return 2 * moving_frames >= static_cast<int>(fs.size()) &&
           moving_frames >= opt.min_placement_frames() && spread <= opt.static_tolerance_mm;
  }

  bool overlaps_marker(int ti, int marker) const {
    const PointTrack& t = tracks[static_cast<std::size_t>(ti)];
    for (int other : body.marker_tracks[static_cast<std::size_t>(marker)]) {
      const PointTrack& o = tracks[static_cast<std::size_t>(other)];
      const int lo = std::max(t.first, o.first), hi = std::min(t.last(), o.last());
      for (int f = lo; f <= hi; ++f)
        if (t.has(f) && o.has(f)) return true;
    }
    return false;
  }

  // Where track ti would go: a marker index, markers_body.size() for a new marker, -1: not here.
  int placement(int ti, Vec3& mean_body) const {
    if (!fits(ti, mean_body)) return -1;
    int nearest = -1;
    double d_min = 1e300;
    for (std::size_t m = 0; m < body.markers_body.size(); ++m) {
      const double d = (body.markers_body[m] - mean_body).norm();
      if (d < d_min) {
        d_min = d;
        nearest = static_cast<int>(m);
      }
    }
    if (nearest >= 0 && d_min <= 0.25 * opt.marker_diameter_mm)
      return overlaps_marker(ti, nearest) ? -1 : nearest;
    if (nearest >= 0 && d_min < opt.marker_diameter_mm) return -1;
    return static_cast<int>(body.markers_body.size());
  }

  void place(int ti, int marker, const Vec3& mean_body) {
    if (marker == static_cast<int>(body.markers_body.size())) {
      body.markers_body.push_back(mean_body);
      body.marker_tracks.emplace_back();
    }
    body.marker_tracks[static_cast<std::size_t>(marker)].push_back(ti);
    members.push_back(ti);
    member_marker.push_back(marker);
  }

  // Poses in frames where fewer than 3 placed tracks are seen: the target so far is
  // identified (src/identify, the tracker's Eq. 1 search) among the points of
  // `candidates` seen there. Only frames that were not posed change.
  void extend_poses(const std::vector<int>& candidates) {
    TargetSet set;
    set.marker_diameter_mm = opt.marker_diameter_mm;
    set.bodies.push_back({"body", body.markers_body});
    IdentifyConfig cfg;
    cfg.point_sigma_mm = std::max(cfg.point_sigma_mm, opt.sigma_mm());
    auto ident = Identifier::create(set, cfg);
    if (!ident) return;  // target not usable for identification (too many markers)
    BodyPoses poses;
    poses.count = 1;
    std::vector<MeasuredPoint> pts;
    for (std::size_t f = 0; f < frames(); ++f) {
      if (body.found[f]) continue;
      pts.clear();
      for (int ti : candidates) {
        const PointTrack& t = tracks[static_cast<std::size_t>(ti)];
        if (!t.has(static_cast<int>(f))) continue;
        MeasuredPoint m;
        m.X_world = t.at(static_cast<int>(f));
        pts.push_back(m);
      }
      if (pts.size() < 3) continue;
      ident->reset();  // frames are not consecutive: full search only
      ident->identify(pts.data(), static_cast<int>(pts.size()), 0, poses);
      if (!poses.bodies[0].found || poses.bodies[0].markers < 3) continue;
      body.found[f] = 1;
      body.T_world_body[f] = poses.bodies[0].T_world_body;
    }
  }

  // Marker positions as the per-axis median of T_world_body^-1 X over all their frames
  // (robust against the few biased points of a partly hidden marker), then the poses.
  void refine() {
    for (int round = 0; round < 2; ++round) {
      compute_poses();
      std::vector<std::vector<Vec3>> samples(body.markers_body.size());
      for (std::size_t i = 0; i < members.size(); ++i) {
        const PointTrack& t = tracks[static_cast<std::size_t>(members[i])];
        for (int f = t.first; f <= t.last(); ++f) {
          if (!t.has(f) || !body.found[static_cast<std::size_t>(f)]) continue;
          samples[static_cast<std::size_t>(member_marker[i])].push_back(
              body.T_world_body[static_cast<std::size_t>(f)].inverse() * t.at(f));
        }
      }
      for (std::size_t m = 0; m < samples.size(); ++m)
        if (!samples[m].empty()) body.markers_body[m] = median_position(samples[m]);
    }
    compute_poses();
  }

  // Origin at the centroid, axes of the temporary frame (world axes at the reference frame).
  void finish() {
    Vec3 c = Vec3::Zero();
    for (const Vec3& m : body.markers_body) c += m;
    c /= static_cast<double>(body.markers_body.size());
    for (Vec3& m : body.markers_body) m -= c;
    Vec3 mean = Vec3::Zero();
    int n = 0;
    for (std::size_t f = 0; f < frames(); ++f) {
      body.T_world_body[f] = body.T_world_body[f] * Eigen::Translation3d(c);
      if (!body.found[f]) continue;
      mean += body.T_world_body[f].translation();
      ++n;
    }
    if (n == 0) return;
    mean /= n;
    double sum2 = 0.0;
    for (std::size_t f = 0; f < frames(); ++f)
      if (body.found[f]) sum2 += (body.T_world_body[f].translation() - mean).squaredNorm();
    body.motion_rms_mm = std::sqrt(sum2 / n);
  }
};

// B is A seen in another time window: B's tracks join A's markers (or are released
// into `released` when unsure); returns true when merged.
bool merge_if_same(Builder& A, const Builder& B, std::vector<int>& released);

}  // namespace mocap::discover::detail
