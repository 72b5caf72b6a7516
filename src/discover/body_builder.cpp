#include "discover/body_builder.h"

#include <Eigen/Geometry>
#include <algorithm>

#include "identify/identifier.h"

namespace mocap::discover {
namespace {

constexpr double kRadToDeg = 57.29577951308232;

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
    for (std::size_t f = 0; f < frames(); ++f) body.found[f] = fit_pose(static_cast<int>(f), body.T_world_body[f]) ? 1 : 0;
  }

  // Largest rotation between two of the poses of `fs` (two-pass diameter estimate), deg.
  double rotation_range_deg(const std::vector<int>& fs) const {
    auto farthest = [&](const Mat3& R_ref, double& angle) {
      int at = fs.front();
      angle = 0.0;
      for (int f : fs) {
        const double a = Eigen::AngleAxisd(R_ref.transpose() * body.T_world_body[static_cast<std::size_t>(f)].linear()).angle();
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
    return a * kRadToDeg;
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
    if (static_cast<int>(fs.size()) < opt.min_covisible_frames) return false;
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
    if (std::sqrt(sum2 / static_cast<double>(y.size())) > tol || far * 20 > static_cast<int>(y.size())) return false;
    if (rotation_range_deg(fs) >= opt.min_pair_rotation_deg) return true;
    // A still body: informative only when the point and the body stayed put while the scene moved.
    int moving_frames = 0;
    double spread = 0.0;
    const Vec3 p0 = t.at(fs.front());
    for (int f : fs) {
      moving_frames += moving[static_cast<std::size_t>(f)] != 0 ? 1 : 0;
      spread = std::max(spread, (t.at(f) - p0).norm());
    }
    return 2 * moving_frames >= static_cast<int>(fs.size()) && 2 * moving_frames >= opt.min_covisible_frames &&
           spread <= opt.static_tolerance_mm;
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
    cfg.point_sigma_mm = std::max(cfg.point_sigma_mm, opt.point_noise_mm);
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

  void refine() {
    for (int round = 0; round < 2; ++round) {
      compute_poses();
      std::vector<Vec3> sum(body.markers_body.size(), Vec3::Zero());
      std::vector<int> count(body.markers_body.size(), 0);
      for (std::size_t i = 0; i < members.size(); ++i) {
        const PointTrack& t = tracks[static_cast<std::size_t>(members[i])];
        for (int f = t.first; f <= t.last(); ++f) {
          if (!t.has(f) || !body.found[static_cast<std::size_t>(f)]) continue;
          sum[static_cast<std::size_t>(member_marker[i])] += body.T_world_body[static_cast<std::size_t>(f)].inverse() * t.at(f);
          ++count[static_cast<std::size_t>(member_marker[i])];
        }
      }
      for (std::size_t m = 0; m < sum.size(); ++m)
        if (count[m] > 0) body.markers_body[m] = sum[m] / static_cast<double>(count[m]);
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

// Seeds a builder from a cluster; false when its reference frame sees fewer than 3 tracks.
bool seed(Builder& b, const std::vector<int>& group) {
  std::vector<int> seen(b.frames(), 0);
  for (int ti : group) {
    const PointTrack& t = b.tracks[static_cast<std::size_t>(ti)];
    for (int f = t.first; f <= t.last(); ++f) seen[static_cast<std::size_t>(f)] += t.has(f) ? 1 : 0;
  }
  const int ref = static_cast<int>(std::max_element(seen.begin(), seen.end()) - seen.begin());
  if (seen[static_cast<std::size_t>(ref)] < 3) return false;
  b.body.reference_frame = ref;
  for (int ti : group) {
    const PointTrack& t = b.tracks[static_cast<std::size_t>(ti)];
    if (t.has(ref)) b.place(ti, static_cast<int>(b.body.markers_body.size()), t.at(ref));
  }
  b.compute_poses();
  return true;
}

// The same body built twice from clusters of different time windows (occlusions cut
// every track between them): B is A when A's target, identified among B's tracks (and
// B's among A's), keeps one constant pose relative to B (rotation within 1 deg,
// translation within 2 mm) over at least min_covisible_frames frames in which A turned
// by min_pair_rotation_deg. B's markers then join A's (or are left to the pool).
// Pose-based test (above); returns false when it cannot decide or says no.
bool same_by_poses(const Builder& A, const Builder& B, Iso3& T_ab) {
  Builder a = A, b = B;
  a.extend_poses(B.members);
  b.extend_poses(A.members);
  std::vector<int> fs;
  for (std::size_t f = 0; f < a.frames(); ++f)
    if (a.body.found[f] && b.body.found[f]) fs.push_back(static_cast<int>(f));
  if (static_cast<int>(fs.size()) < A.opt.min_covisible_frames) return false;
  if (a.rotation_range_deg(fs) < A.opt.min_pair_rotation_deg) return false;
  std::vector<Iso3> rel;
  for (int f : fs)
    rel.push_back(a.body.T_world_body[static_cast<std::size_t>(f)].inverse() * b.body.T_world_body[static_cast<std::size_t>(f)]);
  T_ab = rel[rel.size() / 2];
  for (const Iso3& T : rel) {
    if (Eigen::AngleAxisd(T.linear() * T_ab.linear().transpose()).angle() * kRadToDeg > 1.0) return false;
    if ((T.translation() - T_ab.translation()).norm() > 2.0) return false;
  }
  return true;
}

// Shape-based test for bodies never posed in the same frame (disjoint time windows):
// at least 3 markers of B align with distinct markers of A by one rigid motion, every
// residual within 4 fit tolerances, and no marker of B lands where A has none nearby
// but within one marker diameter (an inconsistent overlap).
bool same_by_shape(const Builder& A, const Builder& B, Iso3& T_ab) {
  for (std::size_t f = 0; f < A.frames(); ++f)
    if (A.body.found[f] && B.body.found[f]) return false;  // seen together: two bodies
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
                double d_min = 1e300;
                for (std::size_t n = 0; n < na; ++n) d_min = std::min(d_min, (T * mb[m] - ma[n]).norm());
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
  return best >= 3;
}

bool merge_if_same(Builder& A, const Builder& B, std::vector<int>& released) {
  Iso3 T_ab = Iso3::Identity();
  if (!same_by_poses(A, B, T_ab) && !same_by_shape(A, B, T_ab)) return false;
  for (std::size_t m = 0; m < B.body.markers_body.size(); ++m) {
    const Vec3 X_a = T_ab * B.body.markers_body[m];
    int nearest = -1;
    double d_min = 1e300;
    for (std::size_t k = 0; k < A.body.markers_body.size(); ++k) {
      const double d = (A.body.markers_body[k] - X_a).norm();
      if (d < d_min) {
        d_min = d;
        nearest = static_cast<int>(k);
      }
    }
    const auto& tracks_m = B.body.marker_tracks[m];
    bool coexists = false;
    if (nearest >= 0)
      for (int ti : tracks_m) coexists = coexists || A.overlaps_marker(ti, nearest);
    int target = -1;
    if (d_min <= 0.25 * A.opt.marker_diameter_mm && !coexists) target = nearest;
    else if (d_min >= A.opt.marker_diameter_mm) target = static_cast<int>(A.body.markers_body.size());
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

}  // namespace

BodyBuild build_bodies(const std::vector<PointTrack>& tracks, const std::vector<std::vector<int>>& groups,
                       const std::vector<char>& moving, const DiscoverOptions& opt) {
  std::vector<Builder> builders;
  std::vector<char> placed(tracks.size(), 0);
  for (const auto& group : groups) {
    Builder b{tracks, moving, opt, {}, {}, {}};
    if (!seed(b, group)) continue;
    // The cluster's other tracks, longest first, until nothing more fits.
    std::vector<int> rest;
    for (int ti : group)
      if (std::find(b.members.begin(), b.members.end(), ti) == b.members.end()) rest.push_back(ti);
    std::stable_sort(rest.begin(), rest.end(), [&](int x, int y) {
      return tracks[static_cast<std::size_t>(x)].seen > tracks[static_cast<std::size_t>(y)].seen;
    });
    auto place_rest = [&](bool recompute) {
      bool any = false;
      for (bool changed = true; changed;) {
        changed = false;
        for (auto it = rest.begin(); it != rest.end();) {
          Vec3 mean;
          const int m = b.placement(*it, mean);
          if (m < 0) {
            ++it;
            continue;
          }
          b.place(*it, m, mean);
          it = rest.erase(it);
          changed = any = true;
        }
        if (changed && recompute) b.compute_poses();
      }
      return any;
    };
    place_rest(true);
    // Windows of the recording where the seed's tracks are not seen (occlusion gaps):
    // identify the target there among the cluster's tracks, place them, repeat.
    for (int round = 0; round < 3 && !rest.empty(); ++round) {
      b.extend_poses(group);
      const bool any = place_rest(false);
      b.compute_poses();
      if (!any) break;
      place_rest(true);
    }
    if (b.body.markers_body.size() < 3) continue;
    for (int ti : b.members) placed[static_cast<std::size_t>(ti)] = 1;
    builders.push_back(std::move(b));
  }
  // Merge duplicates of one body (largest first), then refine.
  std::vector<int> released;
  std::vector<char> merged(builders.size(), 0);
  for (std::size_t i = 0; i < builders.size(); ++i)
    for (std::size_t j = i + 1; j < builders.size(); ++j)
      if (!merged[i] && !merged[j] && merge_if_same(builders[i], builders[j], released)) merged[j] = 1;
  for (int ti : released) placed[static_cast<std::size_t>(ti)] = 0;
  {
    std::vector<Builder> kept;
    for (std::size_t i = 0; i < builders.size(); ++i)
      if (!merged[i]) kept.push_back(std::move(builders[i]));
    builders.swap(kept);
  }
  for (Builder& b : builders) b.refine();
  // Every long track left over goes to the one body it fits, if exactly one.
  std::vector<int> pool;
  for (std::size_t ti = 0; ti < tracks.size(); ++ti)
    if (!placed[ti] && tracks[ti].seen >= opt.min_track_frames) pool.push_back(static_cast<int>(ti));
  std::stable_sort(pool.begin(), pool.end(), [&](int x, int y) {
    return tracks[static_cast<std::size_t>(x)].seen > tracks[static_cast<std::size_t>(y)].seen;
  });
  // Poses in the occlusion gaps of each body from the leftover tracks, then placement.
  for (Builder& b : builders) b.extend_poses(pool);
  BodyBuild out;
  for (int ti : pool) {
    int body = -1, marker = -1, fitting = 0;
    Vec3 mean_body;
    for (std::size_t bi = 0; bi < builders.size(); ++bi) {
      Vec3 mb;
      const int m = builders[bi].placement(ti, mb);
      Vec3 unused;
      if (m < 0 && !builders[bi].fits(ti, unused)) continue;
      ++fitting;
      body = static_cast<int>(bi);
      marker = m;
      mean_body = mb;
    }
    if (fitting == 1 && marker >= 0)
      builders[static_cast<std::size_t>(body)].place(ti, marker, mean_body);
    else
      out.unplaced_tracks.push_back(ti);
  }
  for (Builder& b : builders) {
    b.refine();
    b.finish();
    out.bodies.push_back(std::move(b.body));
  }
  return out;
}

kinematics::CalibrationInput make_calibration_input(const std::vector<DiscoveredBody>& bodies,
                                                    const std::vector<PointTrack>& tracks,
                                                    std::size_t frame_count,
                                                    const DiscoverOptions& opt) {
  kinematics::CalibrationInput input;
  input.frames.resize(frame_count);
  for (std::size_t f = 0; f < frame_count; ++f) {
    auto& frame = input.frames[f];
    frame.bodies.resize(bodies.size());
    for (std::size_t b = 0; b < bodies.size(); ++b) {
      const DiscoveredBody& body = bodies[b];
      kinematics::BodyObservation& obs = frame.bodies[b];
      obs.found = body.found[f] != 0;
      if (!obs.found) continue;
      obs.T_world_body = body.T_world_body[f];
      const double tol = 5.0 * opt.body_fit_tolerance_mm();  // as the pose fit drops points
      for (std::size_t m = 0; m < body.marker_tracks.size(); ++m) {
        for (int ti : body.marker_tracks[m]) {
          const PointTrack& t = tracks[static_cast<std::size_t>(ti)];
          if (!t.has(static_cast<int>(f))) continue;
          const Vec3& X = t.at(static_cast<int>(f));
          if ((obs.T_world_body * body.markers_body[m] - X).norm() > tol) continue;
          obs.markers.push_back({static_cast<int>(m), X});
          break;
        }
      }
    }
  }
  return input;
}

}  // namespace mocap::discover
