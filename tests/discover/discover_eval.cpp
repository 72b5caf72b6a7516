// Acceptance measurement (not a test): `discover_eval REC...` runs discover on each
// simulated recording and prints the comparison with its ground truth
// (discover_truth.h) and the time taken, one line per recording.
#include <chrono>
#include <cstdio>
#include <cstdlib>

#include "discover/frame_points.h"
#include "discover/point_tracker.h"
#include "discover/rigid_groups.h"
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
      mocap::discover::DiscoverOptions opt;
      const auto tracks = mocap::discover::point_tracks(*points, opt).tracks;
      for (std::size_t k = 0; k < tracks.size(); ++k)
        for (int f = tracks[k].first; f <= tracks[k].last(); ++f)
          if (tracks[k].has(f))
            std::fprintf(out, "%zu,%lld,%.3f,%.3f,%.3f\n", k,
                         static_cast<long long>(points->frames[static_cast<std::size_t>(f)].frame),
                         tracks[k].at(f).x(), tracks[k].at(f).y(), tracks[k].at(f).z());
      std::fclose(out);
      if (const char* groups = std::getenv("DISCOVER_DUMP_GROUPS")) {  // rigid clusters
        opt.point_noise_mm = mocap::discover::point_tracks(*points, opt).point_noise_mm;
        const auto moving = mocap::discover::scene_motion(*points, tracks, opt);
        FILE* g = std::fopen(groups, "w");
        for (const auto& group : mocap::discover::group_rigid_tracks(tracks, moving, opt)) {
          for (int ti : group) std::fprintf(g, "%d ", ti);
          std::fprintf(g, "\n");
        }
        std::fclose(g);
      }
    }
    mocap::discover::DiscoverOptions opt;
    auto r = mocap::discover::discover_model(*points, opt, rec,
                                             std::getenv("NO_TRACKER_CAL") == nullptr
                                                 ? mocap::discover::tracker_poses(rec)
                                                 : mocap::discover::PoseSource{});
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
    std::printf(
        "%s: %zu bodies (%d merged), %zu joints, %d unplaced tracks, noise %.3f mm, "
        "frames >= %d / %d, %.2f s: %s\n",
        rec.c_str(), r->targets.bodies.size(), r->stats.merged_bodies, r->model.joints.size(),
        r->stats.unplaced_tracks, r->stats.point_noise_mm, r->stats.min_covisible_frames,
        r->stats.min_placement_frames, s, t->describe().c_str());
    if (std::getenv("DISCOVER_VERBOSE") != nullptr) {
      for (const std::string& line : t->body_lines) std::printf("  %s\n", line.c_str());
      for (const std::string& line : t->joint_lines) std::printf("  %s\n", line.c_str());
    }
  }
  return bad == 0 ? 0 : 1;
}
