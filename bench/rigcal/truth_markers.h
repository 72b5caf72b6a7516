// Design: the simulator's wand truth (gt/markers.csv of `mocap simulate --motion wand`:
// frame,marker,x,y,z then uK,vK,visK for every camera K) for the rig calibration's bench
// tools, read once into one record per marker and frame.
#pragma once

#include <cstdlib>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "core/types.h"

namespace mocap::bench {

struct TruthMarker {
  int frame = 0;
  int marker = 0;
  Vec3 X = Vec3::Zero();    // the simulator's world (mm)
  std::vector<Vec2> px;     // per camera: the projection of the ball's centre
  std::vector<bool> alone;  // per camera: the view is isolated (docs/simulator.md)
};

// Rows with fewer than `cameras` camera triples are skipped.
inline std::vector<TruthMarker> read_truth_markers(const std::string& path, int cameras) {
  std::vector<TruthMarker> out;
  std::ifstream f(path);
  std::string line;
  std::getline(f, line);
  while (std::getline(f, line)) {
    std::stringstream ss(line);
    std::string t;
    std::vector<double> v;
    while (std::getline(ss, t, ',')) v.push_back(std::atof(t.c_str()));
    if (v.size() < static_cast<std::size_t>(5 + 3 * cameras)) continue;
    TruthMarker m;
    m.frame = static_cast<int>(v[0]);
    m.marker = static_cast<int>(v[1]);
    m.X = Vec3(v[2], v[3], v[4]);
    for (std::size_t c = 0; c < static_cast<std::size_t>(cameras); ++c) {
      m.px.emplace_back(v[5 + 3 * c], v[6 + 3 * c]);
      m.alone.push_back(v[7 + 3 * c] == 1.0);
    }
    out.push_back(std::move(m));
  }
  return out;
}

}  // namespace mocap::bench
