#include "discover/body_builder.h"

#include <Eigen/Geometry>
#include <algorithm>

#include "discover/body_builder_detail.h"

namespace mocap::discover {
namespace {

using detail::Builder;

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

}  // namespace

BodyBuild build_bodies(const std::vector<PointTrack>& tracks,
                       const std::vector<std::vector<int>>& groups, const std::vector<char>& moving,
                       const DiscoverOptions& opt) {
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
  // Twice: merge duplicates of one body (largest first), refine, then place every long
  // track left over in the one body it fits, if exactly one. The second merge sees the
  // bodies completed by the first placement (a body built from two time windows may
  // share too few markers before it).
  BodyBuild out;
  for (int round = 0; round < 2; ++round) {
    std::vector<int> released;
    std::vector<char> merged(builders.size(), 0);
    for (std::size_t i = 0; i < builders.size(); ++i)
      for (std::size_t j = i + 1; j < builders.size(); ++j)
        if (!merged[i] && !merged[j] && detail::merge_if_same(builders[i], builders[j], released))
          merged[j] = 1;
    for (int ti : released) placed[static_cast<std::size_t>(ti)] = 0;
    {
      std::vector<Builder> kept;
      for (std::size_t i = 0; i < builders.size(); ++i)
        if (!merged[i]) kept.push_back(std::move(builders[i]));
      builders.swap(kept);
    }
    if (round > 0 && std::none_of(merged.begin(), merged.end(), [](char m) { return m != 0; }))
      break;  // nothing merged: the first placement stands
    for (Builder& b : builders) b.refine();
    std::vector<int> pool;
    for (std::size_t ti = 0; ti < tracks.size(); ++ti)
      if (!placed[ti] && tracks[ti].seen >= opt.min_track_frames)
        pool.push_back(static_cast<int>(ti));
    std::stable_sort(pool.begin(), pool.end(), [&](int x, int y) {
      return tracks[static_cast<std::size_t>(x)].seen > tracks[static_cast<std::size_t>(y)].seen;
    });
    // Poses in the occlusion gaps of each body from the leftover tracks, then placement.
    for (Builder& b : builders) b.extend_poses(pool);
    out.unplaced_tracks.clear();
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
      if (fitting == 1 && marker >= 0) {
        builders[static_cast<std::size_t>(body)].place(ti, marker, mean_body);
        placed[static_cast<std::size_t>(ti)] = 1;
      } else {
        out.unplaced_tracks.push_back(ti);
      }
    }
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
