// Design: see ambiguity.h. Setup-time only (allocates, O(k^3 * k^3) per pair of targets).
#include "identify/ambiguity.h"

#include <cmath>
#include <cstdio>

#include "identify/rigid_fit.h"

namespace mocap {
namespace {

struct Alignment {
  int m = 0;
  double rms_mm = 0.0;
};

// Best alignment of A's markers onto B's, starting from triangle a[3] -> b[3].
Alignment grow(const TargetModel& A, const TargetModel& B, const int* a, const int* b, bool same,
               const IdentifyConfig& config) {
  std::array<int, kMaxMarkers> to_b{};
  to_b.fill(-1);
  std::array<bool, kMaxMarkers> b_used{};
  FitPoints src(3, kMaxMarkers), dst(3, kMaxMarkers);
  int m = 0;
  for (int i = 0; i < 3; ++i) {
    to_b[static_cast<std::size_t>(a[i])] = b[i];
    b_used[static_cast<std::size_t>(b[i])] = true;
    src.col(m) = A.M_body[static_cast<std::size_t>(a[i])];
    dst.col(m) = B.M_body[static_cast<std::size_t>(b[i])];
    ++m;
  }
  const double t2 = config.t_mm * config.t_mm;
  RigidFit fit = fit_rigid(src, dst, m);
  if (!(fit.max_sq_mm2 < t2)) return {};
  for (int ai = 0; ai < A.k; ++ai) {
    if (to_b[static_cast<std::size_t>(ai)] >= 0) continue;
    const Vec3 x = fit.T_dst_src * A.M_body[static_cast<std::size_t>(ai)];
    int best = -1;
    double best2 = t2;
    for (int bi = 0; bi < B.k; ++bi) {
      const double d2 = (B.M_body[static_cast<std::size_t>(bi)] - x).squaredNorm();
      if (!b_used[static_cast<std::size_t>(bi)] && d2 < best2) {
        best = bi;
        best2 = d2;
      }
    }
    if (best < 0) continue;
    src.col(m) = A.M_body[static_cast<std::size_t>(ai)];
    dst.col(m) = B.M_body[static_cast<std::size_t>(best)];
    const RigidFit grown = fit_rigid(src, dst, m + 1);
    if (!(grown.max_sq_mm2 < t2)) continue;
    fit = grown;
    to_b[static_cast<std::size_t>(ai)] = best;
    b_used[static_cast<std::size_t>(best)] = true;
    ++m;
  }
  if (same) {  // the identity correspondence is the target itself, not a confusion
    bool identity = true;
    for (int ai = 0; ai < A.k; ++ai) {
      const int bi = to_b[static_cast<std::size_t>(ai)];
      if (bi >= 0 && bi != ai) identity = false;
    }
    if (identity) return {};
  }
  return Alignment{m, std::sqrt(fit.sum_sq_mm2 / m)};
}

Alignment best_alignment(const TargetModel& A, const TargetModel& B, bool same,
                         const IdentifyConfig& config) {
  Alignment best;
  const double t = config.t_mm;
  const auto& dA = A.dist_mm;
  const auto& dB = B.dist_mm;
  auto close = [t](double x, double y) { return std::abs(x - y) < t; };
  int a[3];
  int b[3];
  for (a[0] = 0; a[0] < A.k; ++a[0])
    for (a[1] = a[0] + 1; a[1] < A.k; ++a[1])
      for (a[2] = a[1] + 1; a[2] < A.k; ++a[2]) {
        const auto a0 = static_cast<std::size_t>(a[0]);
        const auto a1 = static_cast<std::size_t>(a[1]);
        const auto a2 = static_cast<std::size_t>(a[2]);
        for (b[0] = 0; b[0] < B.k; ++b[0])
          for (b[1] = 0; b[1] < B.k; ++b[1]) {
            if (b[1] == b[0]) continue;
            const auto b0 = static_cast<std::size_t>(b[0]);
            const auto b1 = static_cast<std::size_t>(b[1]);
            if (!close(dA[a0][a1], dB[b0][b1])) continue;
            for (b[2] = 0; b[2] < B.k; ++b[2]) {
              if (b[2] == b[0] || b[2] == b[1]) continue;
              const auto b2 = static_cast<std::size_t>(b[2]);
              if (!close(dA[a0][a2], dB[b0][b2]) || !close(dA[a1][a2], dB[b1][b2])) continue;
              if (same && b[0] == a[0] && b[1] == a[1] && b[2] == a[2]) continue;
              const Alignment al = grow(A, B, a, b, same, config);
              if (al.m > best.m || (al.m == best.m && al.m > 0 && al.rms_mm < best.rms_mm))
                best = al;
            }
          }
      }
  return best;
}

std::string fmt(double v) {
  char buf[32];
  std::snprintf(buf, sizeof(buf), "%.2f", v);
  return buf;
}

}  // namespace

std::vector<AmbiguityFinding> find_ambiguities(const std::vector<TargetModel>& models,
                                               const IdentifyConfig& config) {
  std::vector<AmbiguityFinding> out;
  const int nb = static_cast<int>(models.size());
  for (int i = 0; i < nb; ++i) {
    for (int j = i; j < nb; ++j) {
      const TargetModel& A = models[static_cast<std::size_t>(i)];
      const TargetModel& B = models[static_cast<std::size_t>(j)];
      const Alignment al = best_alignment(A, B, i == j, config);
      if (al.m < config.min_markers) continue;
      AmbiguityFinding f;
      f.body_a = i;
      f.body_b = j;
      f.markers = al.m;
      f.rms_mm = al.rms_mm;
      if (i == j) {
        f.message = "targets: body '" + A.name + "': " + std::to_string(al.m) + " of its " +
                    std::to_string(A.k) +
                    " markers map onto other markers of itself within t = " + fmt(config.t_mm) +
                    " mm (rms " + fmt(al.rms_mm) +
                    " mm): symmetric target, its pose can be confused";
      } else {
        f.message = "targets: bodies '" + A.name + "' and '" + B.name +
                    "': " + std::to_string(al.m) + " of the " + std::to_string(A.k) +
                    " markers of '" + A.name + "' align with markers of '" + B.name +
                    "' within t = " + fmt(config.t_mm) + " mm (rms " + fmt(al.rms_mm) +
                    " mm): they can be confused when only those markers are visible";
      }
      out.push_back(std::move(f));
    }
  }
  return out;
}

}  // namespace mocap
