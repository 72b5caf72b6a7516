// Acceptance measurement (not a test): `discover_eval REC...` runs discover on each
// simulated recording and prints the comparison with its ground truth
// (discover_truth.h) and the time taken, one line per recording.
#include <chrono>
#include <cstdio>
#include <cstdlib>

#include "discover/frame_points.h"
#include "discover/point_tracker.h"
#include "discover_truth.h"

int main(int argc, char** argv) {
  int bad = 0;
  for (int i = 1; i < argc; ++i) {
    const std::string rec = argv[i];
    const auto t0 = std::chrono::steady_clock::now();
    auto points = mocap::discover::triangulate_recording(rec);
    if (!points) {
      std::printf("%s: %s\n", rec.c_str(), points.error().message.c_str());
      ++bad;
      continue;
    }
    if (const char* dump = std::getenv("DISCOVER_DUMP_TRACKS")) {  // tracks for analysis
      FILE* out = std::fopen(dump, "w");
      const auto tracks =
          mocap::discover::track_points(*points, mocap::discover::DiscoverOptions{});
      for (std::size_t k = 0; k < tracks.size(); ++k)
        for (int f = tracks[k].first; f <= tracks[k].last(); ++f)
          if (tracks[k].has(f))
            std::fprintf(out, "%zu,%lld,%.3f,%.3f,%.3f\n", k,
                         static_cast<long long>(points->frames[static_cast<std::size_t>(f)].frame),
                         tracks[k].at(f).x(), tracks[k].at(f).y(), tracks[k].at(f).z());
      std::fclose(out);
    }
    auto r = mocap::discover::discover_model(*points, mocap::discover::DiscoverOptions{}, rec);
    const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    if (!r) {
      std::printf("%s: %s\n", rec.c_str(), r.error().message.c_str());
      ++bad;
      continue;
    }
    auto t = mocap::test::compare_with_truth(rec, *r);
    if (!t) {
      std::printf("%s: %s\n", rec.c_str(), t.error().message.c_str());
      ++bad;
      continue;
    }
    std::printf("%s: %zu bodies, %zu joints, %d unplaced tracks, %.2f s: %s\n", rec.c_str(),
                r->targets.bodies.size(), r->model.joints.size(), r->stats.unplaced_tracks, s,
                t->describe().c_str());
  }
  return bad == 0 ? 0 : 1;
}
