#include "discover/point_tracker.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

#include "core/median.h"

namespace mocap::discover {
namespace {

struct Active {
  PointTrack track;
  Vec3 velocity = Vec3::Zero();  // mm/s
  bool has_velocity = false;
  int last_frame = 0;  // frame index of the last measurement
};

double seconds_between(const PointSequence& seq, int a, int b) {
  const double dt =
      1e-9 * static_cast<double>(seq.frames[static_cast<std::size_t>(b)].timestamp_ns -
                                 seq.frames[static_cast<std::size_t>(a)].timestamp_ns);
  return dt > 0.0 ? dt : 0.01 * (b - a);  // non-increasing stamps: assume 100 fps
}

}  // namespace

std::vector<PointTrack> track_points(const PointSequence& seq, const DiscoverOptions& opt) {
  constexpr double kInf = std::numeric_limits<double>::infinity();
  const double sigma = opt.sigma_mm();
  std::vector<PointTrack> done;
  std::vector<Active> active;
  for (int f = 0; f < static_cast<int>(seq.frames.size()); ++f) {
    const std::vector<Vec3>& pts = seq.frames[static_cast<std::size_t>(f)].X_world_mm;
    const std::size_t nt = active.size(), np = pts.size();
    auto continues = [&](const Active& a, const Vec3& from, const Vec3& to, int frame) {
      if (frame + 1 >= static_cast<int>(seq.frames.size())) return false;
      const double dt0 = seconds_between(seq, a.last_frame, frame);
      const double dt1 = seconds_between(seq, frame, frame + 1);
      const Vec3 next = to + (to - from) * (dt1 / dt0);
      const double gate = opt.gate_sigmas * 3.0 * sigma + opt.max_accel_mm_per_s2 * dt1 * dt1;
      for (const Vec3& q : seq.frames[static_cast<std::size_t>(frame + 1)].X_world_mm)
        if ((q - next).norm() <= gate) return true;
      return false;
    };
    // Distances within the gates (kInf outside).
    std::vector<double> d(nt * np, kInf);
    for (std::size_t t = 0; t < nt; ++t) {
      const Active& a = active[t];
      const double dt = seconds_between(seq, a.last_frame, f);
      const Vec3& last = a.track.at(a.last_frame);
      const Vec3 predicted = a.has_velocity ? Vec3(last + a.velocity * dt) : last;
      const double gate = a.has_velocity
                              ? opt.gate_sigmas * 3.0 * sigma + opt.max_accel_mm_per_s2 * dt * dt
                              : opt.gate_sigmas * 2.0 * sigma + opt.max_speed_mm_per_s * dt;
      for (std::size_t p = 0; p < np; ++p) {
        const double dist = (pts[p] - predicted).norm();
        if (dist > gate) continue;
        // A new track (no velocity yet) takes a point only when the velocity it implies
        // predicts a point of the next frame (within the velocity gate): fast markers
        // closer than one frame's travel are told apart by their continuation.
        if (!a.has_velocity && !continues(a, last, pts[p], f)) continue;
        d[t * np + p] = dist;
      }
    }
    auto best_two = [&](std::size_t count, auto at) {
      std::size_t best = count;
      double b1 = kInf, b2 = kInf;
      for (std::size_t i = 0; i < count; ++i) {
        const double v = at(i);
        if (v < b1) {
          b2 = b1;
          b1 = v;
          best = i;
        } else if (v < b2) {
          b2 = v;
        }
      }
      return std::make_tuple(best, b1, b2);
    };
    const double noise_gate = opt.gate_sigmas * 2.0 * sigma;
    auto clear = [&](double best, double second) {
      return second > 2.0 * best && second > best + 2.0 * noise_gate;
    };
    std::vector<int> point_track(np, -1);
    std::vector<bool> track_ends(nt, false);
    for (std::size_t t = 0; t < nt; ++t) {
      const auto [p, b1, b2] = best_two(np, [&](std::size_t i) { return d[t * np + i]; });
      if (p == np) continue;
      const std::size_t point = p;  // (a lambda may not capture a structured binding in C++17)
      const auto [t2, c1, c2] = best_two(nt, [&](std::size_t i) { return d[i * np + point]; });
      if (t2 == t && clear(b1, b2) && clear(c1, c2))
        point_track[p] = static_cast<int>(t);
      else
        track_ends[t] = true;  // ambiguous: end it, the grouping re-links fragments
    }
    std::vector<bool> extended(nt, false);
    for (std::size_t p = 0; p < np; ++p) {
      if (point_track[p] < 0) continue;
      Active& a = active[static_cast<std::size_t>(point_track[p])];
      const double dt = seconds_between(seq, a.last_frame, f);
      a.velocity = (pts[p] - a.track.at(a.last_frame)) / dt;
      a.has_velocity = true;
      while (a.track.last() < f - 1) a.track.X_world_mm.push_back(Vec3::Constant(std::nan("")));
      a.track.X_world_mm.push_back(pts[p]);
      ++a.track.seen;
      a.last_frame = f;
      extended[static_cast<std::size_t>(point_track[p])] = true;
    }
    std::vector<Active> next;
    next.reserve(nt + np);
    for (std::size_t t = 0; t < nt; ++t) {
      Active& a = active[t];
      if (!extended[t] && (track_ends[t] || f - a.last_frame > opt.max_gap_frames))
        done.push_back(std::move(a.track));
      else
        next.push_back(std::move(a));
    }
    for (std::size_t p = 0; p < np; ++p) {
      if (point_track[p] >= 0) continue;
      Active a;
      a.track.first = f;
      a.track.X_world_mm.push_back(pts[p]);
      a.track.seen = 1;
      a.last_frame = f;
      next.push_back(std::move(a));
    }
    active = std::move(next);
  }
  for (Active& a : active) done.push_back(std::move(a.track));
  std::sort(done.begin(), done.end(),
            [](const PointTrack& a, const PointTrack& b) { return a.first < b.first; });
  return done;
}

std::vector<PointTrack> stitch_still_fragments(std::vector<PointTrack> tracks,
                                               const DiscoverOptions& opt) {
  // Median position of every still track (NaN x: moving or too short).
  std::vector<Vec3> still(tracks.size(), Vec3::Constant(std::nan("")));
  for (std::size_t k = 0; k < tracks.size(); ++k) {
    const PointTrack& t = tracks[k];
    if (t.seen < 3) continue;
    std::vector<Vec3> pts;
    for (int f = t.first; f <= t.last(); ++f)
      if (t.has(f)) pts.push_back(t.at(f));
    const Vec3 med = median_position(pts);
    bool is_still = true;
    for (int f = t.first; f <= t.last() && is_still; ++f)
      is_still = !t.has(f) || (t.at(f) - med).norm() <= opt.static_tolerance_mm;
    if (is_still) still[k] = med;
  }
  const double gate = opt.gate_sigmas * 3.0 * opt.sigma_mm();
  std::vector<char> absorbed(tracks.size(), 0);
  for (std::size_t a = 0; a < tracks.size(); ++a) {  // tracks are sorted by first frame
    if (absorbed[a] || std::isnan(still[a].x())) continue;
    for (std::size_t b = a + 1; b < tracks.size(); ++b) {
      if (absorbed[b] || std::isnan(still[b].x())) continue;
      PointTrack& ta = tracks[a];
      const PointTrack& tb = tracks[b];
      if (tb.first <= ta.last() || (still[a] - still[b]).norm() > gate) continue;
      while (ta.last() < tb.first - 1) ta.X_world_mm.push_back(Vec3::Constant(std::nan("")));
      ta.X_world_mm.insert(ta.X_world_mm.end(), tb.X_world_mm.begin(), tb.X_world_mm.end());
      ta.seen += tb.seen;
      absorbed[b] = 1;
    }
  }
  std::vector<PointTrack> out;
  for (std::size_t k = 0; k < tracks.size(); ++k)
    if (!absorbed[k]) out.push_back(std::move(tracks[k]));
  return out;
}

TrackedPoints point_tracks(const PointSequence& seq, const DiscoverOptions& options) {
  DiscoverOptions opt = options;
  if (!(opt.point_noise_mm > 0.0)) {
    DiscoverOptions first = opt;
    first.point_noise_mm = opt.provisional_noise_mm;
    opt.point_noise_mm = estimate_point_noise(track_points(seq, first), first.point_noise_mm);
  }
  return {stitch_still_fragments(track_points(seq, opt), opt), opt.point_noise_mm};
}

double estimate_point_noise(const std::vector<PointTrack>& tracks, double fallback) {
  std::array<std::vector<double>, 3> d3;
  for (const PointTrack& t : tracks)
    for (int f = t.first; f + 3 <= t.last(); ++f) {
      if (!t.has(f) || !t.has(f + 1) || !t.has(f + 2) || !t.has(f + 3)) continue;
      const Vec3 d = t.at(f + 3) - 3.0 * t.at(f + 2) + 3.0 * t.at(f + 1) - t.at(f);
      for (int k = 0; k < 3; ++k) d3[static_cast<std::size_t>(k)].push_back(d[k]);
    }
  if (d3[0].size() < 30) return fallback;
  double worst = 0.0;
  for (auto& v : d3) {
    const double m = median_in_place(v);
    for (double& x : v) x = std::abs(x - m);
    worst = std::max(worst, 1.4826 * median_in_place(v) / std::sqrt(20.0));
  }
  return std::max(0.005, worst);
}

}  // namespace mocap::discover
