#include "discover/rigid_groups.h"

#include <algorithm>
#include <numeric>

#include "core/median.h"
#include "core/units.h"

namespace mocap::discover {
namespace {

double max_angle_deg(const std::vector<Vec3>& dirs, const Vec3& ref, std::size_t* arg) {
  double best = -2.0;
  std::size_t at = 0;
  for (std::size_t i = 0; i < dirs.size(); ++i) {
    const double c = -dirs[i].dot(ref);  // largest angle = most negative cosine
    if (c > best) {
      best = c;
      at = i;
    }
  }
  if (arg != nullptr) *arg = at;
  return std::acos(std::clamp(-best, -1.0, 1.0)) * kDegPerRad;
}

// Largest deviation of a track from its median position over `frames`.
double spread_mm(const PointTrack& t, const std::vector<int>& frames) {
  std::vector<Vec3> pts;
  for (int f : frames) pts.push_back(t.at(f));
  const Vec3 med = median_position(pts);
  double worst = 0.0;
  for (int f : frames) worst = std::max(worst, (t.at(f) - med).norm());
  return worst;
}

}  // namespace

std::vector<char> scene_motion(const PointSequence& seq, const std::vector<PointTrack>& tracks,
                               const DiscoverOptions& opt) {
  std::vector<char> moving(seq.frames.size(), 0);
  for (const PointTrack& t : tracks) {
    if (t.seen < opt.min_track_frames) continue;
    for (int f = t.first + 1; f <= t.last(); ++f) {
      if (!t.has(f) || !t.has(f - 1)) continue;
      const double dt =
          1e-9 * static_cast<double>(seq.frames[static_cast<std::size_t>(f)].timestamp_ns -
                                     seq.frames[static_cast<std::size_t>(f - 1)].timestamp_ns);
      const double step = (t.at(f) - t.at(f - 1)).norm();
      // Noise alone moves a point by ~2 sigma per frame: require more than that too.
      if (dt > 0.0 && step / dt > opt.min_scene_speed_mm_per_s && step > 6.0 * opt.sigma_mm())
        moving[static_cast<std::size_t>(f)] = 1;
    }
  }
  return moving;
}

PairRelation classify_pair(const PointTrack& a, const PointTrack& b,
                           const std::vector<char>& moving, const DiscoverOptions& opt) {
  const int lo = std::max(a.first, b.first), hi = std::min(a.last(), b.last());
  if (hi - lo + 1 < 5) return PairRelation::kUnknown;
  std::vector<int> frames;
  for (int f = lo; f <= hi; ++f)
    if (a.has(f) && b.has(f)) frames.push_back(f);
  const int n_all = static_cast<int>(frames.size());
  if (n_all < 5) return PairRelation::kUnknown;
  if (n_all > opt.max_pair_frames) {
    std::vector<int> sub;
    for (int i = 0; i < opt.max_pair_frames; ++i)
      sub.push_back(
          frames[static_cast<std::size_t>(static_cast<long>(i) * n_all / opt.max_pair_frames)]);
    frames = std::move(sub);
  }
  std::vector<double> dist;
  std::vector<Vec3> dirs;
  for (int f : frames) {
    const Vec3 v = b.at(f) - a.at(f);
    dist.push_back(v.norm());
    dirs.push_back(v.normalized());
  }
  const double med = median_in_place(dist);
  std::vector<double> dev(dist.size());
  for (std::size_t i = 0; i < dist.size(); ++i) dev[i] = std::abs(dist[i] - med);
  const double robust_std = 1.4826 * median_in_place(dev);
  const double bound = opt.pair_distance_std_mm();
  const double far = static_cast<double>(std::count_if(dev.begin(), dev.end(),
                                                       [&](double x) { return x > 4.0 * bound; })) /
                     static_cast<double>(dev.size());
  if (robust_std > 2.0 * bound || far > 0.2) return PairRelation::kNonRigid;
  if (n_all < opt.min_covisible_frames() || robust_std > bound || far > 0.05)
    return PairRelation::kUnknown;
  std::size_t i1 = 0;
  max_angle_deg(dirs, dirs[0], &i1);
  const double turned = max_angle_deg(dirs, dirs[i1], nullptr);
  if (turned / kDegPerRad >= opt.min_pair_turn_rad(med)) return PairRelation::kRigid;
  const int moving_frames =
      static_cast<int>(std::count_if(frames.begin(), frames.end(), [&](int f) {
        return moving[static_cast<std::size_t>(f)] != 0;
      }));
  if (2 * moving_frames >= static_cast<int>(frames.size()) &&
      moving_frames >= opt.min_covisible_frames() &&
      spread_mm(a, frames) <= opt.static_tolerance_mm &&
      spread_mm(b, frames) <= opt.static_tolerance_mm)
    return PairRelation::kRigid;
  return PairRelation::kUnknown;
}

std::vector<std::vector<int>> group_rigid_tracks(const std::vector<PointTrack>& tracks,
                                                 const std::vector<char>& moving,
                                                 const DiscoverOptions& opt) {
  std::vector<int> nodes;
  for (int i = 0; i < static_cast<int>(tracks.size()); ++i)
    if (tracks[static_cast<std::size_t>(i)].seen >= opt.min_track_frames) nodes.push_back(i);
  const std::size_t n = nodes.size();
  std::vector<PairRelation> rel(n * n, PairRelation::kUnknown);
  struct Edge {
    std::size_t a, b;
    int common;
  };
  std::vector<Edge> edges;
  for (std::size_t i = 0; i < n; ++i) {
    for (std::size_t j = i + 1; j < n; ++j) {
      const PointTrack& ta = tracks[static_cast<std::size_t>(nodes[i])];
      const PointTrack& tb = tracks[static_cast<std::size_t>(nodes[j])];
      const PairRelation r = classify_pair(ta, tb, moving, opt);
      rel[i * n + j] = rel[j * n + i] = r;
      if (r == PairRelation::kRigid)
        edges.push_back({i, j, std::min(ta.last(), tb.last()) - std::max(ta.first, tb.first)});
    }
  }
  std::stable_sort(edges.begin(), edges.end(),
                   [](const Edge& x, const Edge& y) { return x.common > y.common; });
  std::vector<std::size_t> cluster(n);
  std::iota(cluster.begin(), cluster.end(), 0);
  std::vector<std::vector<std::size_t>> members(n);
  for (std::size_t i = 0; i < n; ++i) members[i] = {i};
  for (bool merged = true; merged;) {
    merged = false;
    for (const Edge& e : edges) {
      const std::size_t x = cluster[e.a], y = cluster[e.b];
      if (x == y) continue;
      int rigid = 0;
      bool conflict = false;
      for (std::size_t p : members[x]) {
        for (std::size_t q : members[y]) {
          const PairRelation r = rel[p * n + q];
          conflict = conflict || r == PairRelation::kNonRigid;
          rigid += r == PairRelation::kRigid ? 1 : 0;
        }
      }
      const std::size_t need = std::min<std::size_t>(3, members[x].size() * members[y].size());
      if (conflict || static_cast<std::size_t>(rigid) < need) continue;
      for (std::size_t p : members[y]) cluster[p] = x;
      members[x].insert(members[x].end(), members[y].begin(), members[y].end());
      members[y].clear();
      merged = true;
    }
  }
  std::vector<std::vector<int>> groups;
  for (const auto& m : members) {
    if (m.size() < 3) continue;
    std::vector<int> g;
    for (std::size_t i : m) g.push_back(nodes[i]);
    std::sort(g.begin(), g.end());
    groups.push_back(std::move(g));
  }
  std::stable_sort(groups.begin(), groups.end(),
                   [](const auto& a, const auto& b) { return a.size() > b.size(); });
  return groups;
}

}  // namespace mocap::discover
