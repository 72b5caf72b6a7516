// Design: random scenes for the identification tests and benchmarks: random targets
// (distinct pair distances), random poses, occlusion, Gaussian noise, stray points kept
// away from every true marker position, shuffled point order, ground truth per marker.
#pragma once

#include <algorithm>
#include <cmath>
#include <numeric>
#include <random>
#include <vector>

#include "formats/targets_yaml.h"
#include "identify/identify_types.h"

namespace mocap::test {

inline Mat3 random_rotation(std::mt19937_64& rng) {
  std::normal_distribution<double> g(0.0, 1.0);
  Quat q(g(rng), g(rng), g(rng), g(rng));
  q.normalize();
  return q.toRotationMatrix();
}

// k markers at min_radius_mm..radius_mm from the origin, pairwise >= 25 mm apart, all pair
// distances differing by more than min_gap_mm.
inline MarkerTarget random_target(std::mt19937_64& rng, int k, const std::string& name,
                                  double radius_mm = 75.0, double min_gap_mm = 3.0,
                                  double min_radius_mm = 40.0) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (;;) {  // markers added one at a time; restart when stuck
    MarkerTarget t;
    t.name = name;
    std::vector<double> d;  // pair distances so far
    for (int tries = 0; tries < 2000 && static_cast<int>(t.markers_body.size()) < k; ++tries) {
      const Vec3 p(u(rng), u(rng), u(rng));
      if (p.norm() > 1.0 || p.norm() * radius_mm < min_radius_mm) continue;
      const Vec3 x = p * radius_mm;
      std::vector<double> nd;
      bool ok = true;
      for (const Vec3& q : t.markers_body) {
        const double dist = (q - x).norm();
        ok = ok && dist >= 25.0;
        nd.push_back(dist);
      }
      for (std::size_t i = 0; ok && i < nd.size(); ++i) {
        for (double e : d) ok = ok && std::abs(nd[i] - e) > min_gap_mm;
        for (std::size_t j = i + 1; ok && j < nd.size(); ++j)
          ok = std::abs(nd[i] - nd[j]) > min_gap_mm;
      }
      if (!ok) continue;
      t.markers_body.push_back(x);
      d.insert(d.end(), nd.begin(), nd.end());
    }
    if (static_cast<int>(t.markers_body.size()) == k) return t;
  }
}

struct Scene {
  std::vector<MeasuredPoint> pts;
  std::vector<std::vector<int>> truth;  // truth[body][marker] = point index, -1 if occluded
  std::vector<Iso3> T_world_body;
};

struct SceneOptions {
  double noise_mm = 0.0;
  int strays = 0;
  bool occlude = false;  // random occlusion down to min_visible markers per body
  int min_visible = 3;
  double spacing_mm = 300.0;  // body centres on a grid this far apart
};

// Poses: given (or random on a grid); every point gets its own blob in each camera.
inline Scene make_scene(std::mt19937_64& rng, const TargetSet& set, const SceneOptions& opt,
                        const std::vector<Iso3>* poses = nullptr) {
  Scene s;
  std::normal_distribution<double> noise(0.0, opt.noise_mm);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const int nb = static_cast<int>(set.bodies.size());
  std::vector<Vec3> all_true;
  std::vector<std::pair<int, int>> owner;  // (body, marker) of each point, (-1,-1) stray
  Vec3 lo = Vec3::Constant(1e9), hi = Vec3::Constant(-1e9);
  for (int b = 0; b < nb; ++b) {
    Iso3 T;
    if (poses) {
      T = (*poses)[static_cast<std::size_t>(b)];
    } else {
      T = Iso3::Identity();
      T.linear() = random_rotation(rng);
      T.translation() = Vec3((b % 4) * opt.spacing_mm, (b / 4) * opt.spacing_mm, 2000.0) +
                        Vec3(u(rng), u(rng), u(rng)) * 50.0;
    }
    s.T_world_body.push_back(T);
    const auto& M = set.bodies[static_cast<std::size_t>(b)].markers_body;
    const int k = static_cast<int>(M.size());
    std::vector<int> order(static_cast<std::size_t>(k));
    std::iota(order.begin(), order.end(), 0);
    std::shuffle(order.begin(), order.end(), rng);
    int visible = k;
    if (opt.occlude)
      visible = opt.min_visible + static_cast<int>(u(rng) * (k - opt.min_visible + 1) * 0.999999);
    s.truth.emplace_back(static_cast<std::size_t>(k), -1);
    for (int i = 0; i < k; ++i) {
      const Vec3 X = T * M[static_cast<std::size_t>(order[static_cast<std::size_t>(i)])];
      all_true.push_back(X);
      lo = lo.cwiseMin(X);
      hi = hi.cwiseMax(X);
      if (i >= visible) continue;
      MeasuredPoint p;
      p.X_world = X + (opt.noise_mm > 0 ? Vec3(noise(rng), noise(rng), noise(rng)) : Vec3::Zero());
      s.pts.push_back(p);
      owner.emplace_back(b, order[static_cast<std::size_t>(i)]);
    }
  }
  lo -= Vec3::Constant(100.0);
  hi += Vec3::Constant(100.0);
  for (int i = 0; i < opt.strays;) {
    const Vec3 X(lo.x() + u(rng) * (hi.x() - lo.x()), lo.y() + u(rng) * (hi.y() - lo.y()),
                 lo.z() + u(rng) * (hi.z() - lo.z()));
    bool far = true;
    for (const Vec3& Y : all_true) far = far && (X - Y).norm() > 12.0;  // a marker diameter
    if (!far) continue;
    MeasuredPoint p;
    p.X_world = X;
    s.pts.push_back(p);
    owner.emplace_back(-1, -1);
    ++i;
  }
  // Shuffle the point order, then assign blobs and record the truth.
  std::vector<int> perm(s.pts.size());
  std::iota(perm.begin(), perm.end(), 0);
  std::shuffle(perm.begin(), perm.end(), rng);
  std::vector<MeasuredPoint> shuffled(s.pts.size());
  for (std::size_t i = 0; i < perm.size(); ++i) {
    const auto src = static_cast<std::size_t>(perm[i]);
    shuffled[i] = s.pts[src];
    shuffled[i].blob_index = {static_cast<std::int16_t>(i), static_cast<std::int16_t>(i)};
    if (owner[src].first >= 0)
      s.truth[static_cast<std::size_t>(owner[src].first)]
             [static_cast<std::size_t>(owner[src].second)] = static_cast<int>(i);
  }
  s.pts = std::move(shuffled);
  return s;
}

// True when the found pose of `body` uses only its own true points, on the right markers.
inline bool identity_correct(const Scene& s, int body, const BodyPose& pose) {
  const auto& tr = s.truth[static_cast<std::size_t>(body)];
  for (std::size_t c = 0; c < tr.size(); ++c) {
    const int p = pose.point_index_of_marker[c];
    if (p >= 0 && p != tr[c]) return false;
  }
  return true;
}

// Under sanitizers the randomized trials are scaled down (10x) to keep runtime low.
inline int scaled_trials(int n) {
#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__)
  return std::max(1, n / 10);
#else
  return n;
#endif
}

}  // namespace mocap::test
