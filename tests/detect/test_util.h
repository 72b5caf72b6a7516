// Design: small helpers shared by the detector tests: run a detector on a synthetic
// image, and match detected blobs to true spots (nearest within a radius).
#pragma once

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <vector>

#include "detect/blob_detector.h"
#include "tests/detect/synth.h"

namespace mocap::detect::test {

inline BlobDetector make_detector(const DetectorConfig& cfg, int w, int h) {
  auto d = BlobDetector::create(cfg, w, h);
  EXPECT_TRUE(d.ok()) << (d.ok() ? "" : d.error().message);
  return std::move(d.value());
}

struct MatchStats {
  int matched = 0;
  int missed = 0;
  int extra = 0;
  double rms_px = 0.0;
  double max_px = 0.0;
  std::vector<double> errors_px;
};

// Matches each spot to the nearest blob within gate_px (each blob used once).
inline MatchStats match(const std::vector<Spot>& spots, const BlobList& blobs,
                        double gate_px = 1.0) {
  MatchStats m;
  std::vector<bool> used(blobs.size(), false);
  double sq = 0.0;
  for (const Spot& s : spots) {
    int best = -1;
    double best_d = gate_px;
    for (std::size_t i = 0; i < blobs.size(); ++i) {
      const double d = std::hypot(blobs[i].x_px - s.x, blobs[i].y_px - s.y);
      if (!used[i] && d < best_d) {
        best_d = d;
        best = static_cast<int>(i);
      }
    }
    if (best < 0) {
      ++m.missed;
      continue;
    }
    used[static_cast<std::size_t>(best)] = true;
    ++m.matched;
    sq += best_d * best_d;
    m.max_px = std::max(m.max_px, best_d);
    m.errors_px.push_back(best_d);
  }
  for (bool u : used) m.extra += u ? 0 : 1;
  m.rms_px = m.matched > 0 ? std::sqrt(sq / m.matched) : 0.0;
  return m;
}

// Field-by-field bit equality (padding bytes are not compared).
inline bool same_blob(const Blob& a, const Blob& b) {
  auto bits = [](auto v) {
    std::uint64_t u = 0;
    std::memcpy(&u, &v, sizeof v);
    return u;
  };
  return bits(a.x_px) == bits(b.x_px) && bits(a.y_px) == bits(b.y_px) &&
         bits(a.area_px) == bits(b.area_px) && bits(a.sum_dn) == bits(b.sum_dn) &&
         a.peak_dn == b.peak_dn && a.background_dn == b.background_dn && a.x_min == b.x_min &&
         a.x_max == b.x_max && a.y_min == b.y_min && a.y_max == b.y_max &&
         bits(a.major_axis_px) == bits(b.major_axis_px) &&
         bits(a.minor_axis_px) == bits(b.minor_axis_px) && bits(a.roundness) == bits(b.roundness) &&
         bits(a.eccentricity) == bits(b.eccentricity) &&
         bits(a.orientation_rad) == bits(b.orientation_rad) && a.flags == b.flags;
}

}  // namespace mocap::detect::test
