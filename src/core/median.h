// Design: the median, the one robust location statistic of the offline code (rig
// calibration, discover's noise estimate and rigidity tests, export frame rates): one
// nth_element pass, O(n), the upper median for even sizes. Not for the hot path (it
// reorders and may be handed a copy). The per-axis median of 3D positions is the
// componentwise median (robust against a few biased points, e.g. a partly hidden ball).
#pragma once

#include <algorithm>
#include <cstddef>
#include <vector>

#include "core/types.h"

namespace mocap {

// Of the first n values at v (reordered; n > 0): for fixed arrays, no allocation.
template <class T>
T median_in_place(T* v, std::size_t n) noexcept {
  T* mid = v + n / 2;
  std::nth_element(v, mid, v + n);
  return *mid;
}

// Reorders v; v must not be empty.
template <class T>
T median_in_place(std::vector<T>& v) {
  return median_in_place(v.data(), v.size());
}

// Componentwise median of positions; pts must not be empty.
inline Vec3 median_position(const std::vector<Vec3>& pts) {
  std::vector<double> c(pts.size());
  Vec3 m;
  for (int a = 0; a < 3; ++a) {
    for (std::size_t i = 0; i < pts.size(); ++i) c[i] = pts[i][a];
    m[a] = median_in_place(c);
  }
  return m;
}

}  // namespace mocap
