// Design: the error of the wand balls' image centres against the renderer's truth, the
// figure behind the rig calibration's precision (docs/rig_calibration.md, "Partly hidden
// wand balls"). Renders a wand recording (or reads one with gt/markers.csv), detects and
// labels the wand in every image exactly as `mocap calibrate-rig` does, and prints per
// wand marker the mean (bias) and standard deviation of the centre's error along the
// wand's image axis (from marker 0 towards the last marker) and across it.
// The end balls' bias is also given combined, signed away from the rod (outwards), the
// figure that stretches the wand. Whole balls and partly hidden ones (less round, kept
// as wand balls) are counted apart. With `axis`, RIGCAL_ROD_CUT=a,b,c runs each fixed cut
// in turn (default: the cut chosen from the recording).
// Usage: wand_centres [frames] [seed] [cameras] [centroid|edge|axis]
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "formats/rig_yaml.h"
#include "rigcal/rig_calibrator.h"
#include "sim/wand_sim.h"
#include "stereo/two_view.h"
#include "truth_markers.h"

using namespace mocap;

namespace {

struct Acc {
  double n = 0, s = 0, ss = 0;
  void add(double v) {
    n += 1;
    s += v;
    ss += v * v;
  }
  double mean() const { return n > 0 ? s / n : 0.0; }
  double sd() const { return n > 1 ? std::sqrt(std::max(ss / n - mean() * mean(), 0.0)) : 0.0; }
};

// (frame, marker) -> per camera the projection of the ball's centre.
std::map<std::pair<int, int>, std::vector<Vec2>> truth_by_frame(const std::string& dir,
                                                                int cameras) {
  std::map<std::pair<int, int>, std::vector<Vec2>> gt;
  for (const bench::TruthMarker& m : bench::read_truth_markers(dir + "/gt/markers.csv", cameras))
    gt[{m.frame, m.marker}] = m.px;
  return gt;
}

}  // namespace

int main(int argc, char** argv) {
  const int frames = argc > 1 ? std::atoi(argv[1]) : 300;
  const auto seed = static_cast<std::uint64_t>(argc > 2 ? std::atoll(argv[2]) : 1);
  const int cameras = argc > 3 ? std::atoi(argv[3]) : 4;
  const std::string centres = argc > 4 ? argv[4] : "axis";
  const std::string dir = (std::filesystem::temp_directory_path() /
                           ("wand_centres_" + std::to_string(seed) + "_" + std::to_string(cameras) +
                            "_" + std::to_string(frames)))
                              .string();
  sim::SimOptions so;
  so.frames = frames;
  so.seed = seed;
  so.cameras = cameras;
  if (!std::filesystem::exists(dir + "/gt/markers.csv")) {
    auto w = sim::write_calibration_recording(so, sim::CalibObjectKind::kWand, dir);
    if (!w) {
      std::fprintf(stderr, "%s\n", w.error().message.c_str());
      return 1;
    }
  }
  auto truth = load_rig(dir + "/gt/rig_true.yaml");
  if (!truth) return 1;
  const WandSpec wand = sim::default_calibration_objects().wand;
  rigcal::RigCalOptions opt;
  opt.edge_centres = centres != "centroid";
  std::vector<double> cuts;
  if (const char* r = std::getenv("RIGCAL_ROD_CUT")) {
    std::stringstream list(r);
    std::string item;
    while (std::getline(list, item, ',')) cuts.push_back(std::atof(item.c_str()));
  }
  if (cuts.empty()) cuts.push_back(0.0);
  const auto gt = truth_by_frame(dir, cameras);
  for (double cut : cuts) {
    opt.rod_cut_deg = cut;
    auto detected =
        rigcal::detect_recording(dir, opt, &truth->cameras, centres == "axis" ? &wand : nullptr);
    if (!detected) {
      std::fprintf(stderr, "%s\n", detected.error().message.c_str());
      return 1;
    }
    const rigcal::FrameBlobs* blobs = &detected->blobs;
    const std::size_t M = wand.markers_mm.size();
    // Per class: [0] whole balls, [1] partly hidden ones (less round, kept as wand balls).
    std::vector<Acc> along[2] = {std::vector<Acc>(M), std::vector<Acc>(M)};
    std::vector<Acc> across[2] = {std::vector<Acc>(M), std::vector<Acc>(M)};
    Acc outward[2];
    std::vector<int> order;
    std::vector<Vec2> scaled;
    for (std::size_t fi = 0; fi < blobs->size(); ++fi) {
      for (int c = 0; c < cameras; ++c) {
        const auto& pts = (*blobs)[fi][static_cast<std::size_t>(c)];
        const CameraModel& cam = truth->cameras[static_cast<std::size_t>(c)];
        scaled.clear();
        std::vector<std::size_t> idx;
        for (std::size_t i = 0; i < pts.size(); ++i) {
          Vec2 xn;
          if (!undistort_pixel(cam, pts[i], xn)) continue;
          scaled.push_back(to_scaled(cam, xn));
          idx.push_back(i);
        }
        if (rigcal::label_wand(wand, opt.label, scaled, order) != rigcal::LabelStatus::kOk)
          continue;
        const auto g0 = gt.find({static_cast<int>(fi), 0});
        const auto g1 = gt.find({static_cast<int>(fi), static_cast<int>(M - 1)});
        if (g0 == gt.end() || g1 == gt.end()) continue;
        const Vec2 u =
            (g1->second[static_cast<std::size_t>(c)] - g0->second[static_cast<std::size_t>(c)])
                .normalized();
        const Vec2 n(-u.y(), u.x());
        for (std::size_t m = 0; m < M; ++m) {
          const auto g = gt.find({static_cast<int>(fi), static_cast<int>(m)});
          if (g == gt.end()) continue;
          const std::size_t slot = idx[static_cast<std::size_t>(order[m])];
          const Vec2 e = pts[slot] - g->second[static_cast<std::size_t>(c)];
          if (e.norm() > 1.0) continue;
          const auto& info = detected->info[fi][static_cast<std::size_t>(c)];
          const int k = slot < info.size() && info[slot].partly_hidden ? 1 : 0;
          along[k][m].add(e.dot(u));
          across[k][m].add(e.dot(n));
          if (m == 0) outward[k].add(-e.dot(u));
          if (m + 1 == M) outward[k].add(e.dot(u));
        }
      }
    }
    std::printf("wand centres: %d frames, seed %llu, %d cameras, centres %s", frames,
                static_cast<unsigned long long>(seed), cameras, centres.c_str());
    if (detected->rod_cut.end_ball_views > 0)  // only the axis method has a rod-side cut
      std::printf(", rod-side cut %.0f deg (%s)", detected->rod_cut.cut_deg,
                  detected->rod_cut.from_recording ? "chosen" : "fixed");
    std::printf("\n");
    for (int k = 0; k < 2; ++k) {
      std::printf("  %s balls:\n", k == 0 ? "whole" : "partly hidden");
      for (std::size_t m = 0; m < M; ++m)
        std::printf(
            "    marker %zu (%5.0f mm): %6.0f views  along mean %+.4f sd %.4f px   across "
            "mean %+.4f sd %.4f px\n",
            m, wand.markers_mm[m], along[k][m].n, along[k][m].mean(), along[k][m].sd(),
            across[k][m].mean(), across[k][m].sd());
      std::printf("    end balls outwards: mean %+.5f px (standard error %.5f) over %.0f views\n",
                  outward[k].mean(), outward[k].sd() / std::sqrt(std::max(outward[k].n - 1.0, 1.0)),
                  outward[k].n);
    }
  }
  return 0;
}
