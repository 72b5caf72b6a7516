// Design: see frame_writer.h. The second render thread is started per call and joined
// before it returns, so a StereoRender is used by one thread at a time.
#include "sim/frame_writer.h"

#include <filesystem>
#include <system_error>
#include <thread>
#include <utility>

#include "formats/rig_yaml.h"
#include "sim/motion.h"

namespace mocap::sim {
namespace {

Expected<void> make_dir(const std::string& path) {
  std::error_code ec;
  std::filesystem::create_directories(path, ec);
  if (ec || !std::filesystem::is_directory(path, ec)) {
    return make_error(path, "",
                      "cannot create directory" + (ec ? ": " + ec.message() : std::string()));
  }
  return {};
}

}  // namespace

Expected<StereoRender> StereoRender::create(const SimScene& scene, int threads) {
  auto ws = RenderWorkspace::create(scene);
  if (!ws) return ws.error();
  return StereoRender(scene, std::move(ws).value(), threads);
}

StereoRender::StereoRender(const SimScene& scene, RenderWorkspace ws, int threads)
    : scene_(&scene),
      workspaces_{ws, std::move(ws)},  // copies the read-only lattices instead of recomputing
      threads_(threads) {}

Expected<void> StereoRender::render(const SceneState& state, const std::array<Image*, 2>& images,
                                    const std::function<Expected<void>(int camera)>& after) {
  std::array<Expected<void>, 2> results;
  auto job = [&](int c) {
    const auto uc = static_cast<std::size_t>(c);
    if (!sim::render(*scene_, state, c, workspaces_[uc], *images[uc])) {
      results[uc] = make_error("simulate", "render", "camera " + std::to_string(c) + " failed");
    } else if (after) {
      results[uc] = after(c);
    }
  };
  if (threads_ >= 2) {
    std::thread t1(job, 1);
    job(0);
    t1.join();
  } else {
    job(0);
    job(1);
  }
  for (Expected<void>& r : results) {
    if (!r) return r;
  }
  return {};
}

Expected<std::vector<FrameEntry>> begin_recording(const std::string& dir, const Rig& rig,
                                                  int frames, double fps) {
  std::vector<std::string> dirs = {dir, dir + "/gt"};
  for (const CameraModel& c : rig.cameras) dirs.push_back(dir + "/" + c.name);
  for (const std::string& d : dirs) {
    if (auto r = make_dir(d); !r) return r.error();
  }
  std::vector<FrameEntry> entries;
  entries.reserve(static_cast<std::size_t>(frames));
  for (int f = 0; f < frames; ++f) entries.push_back(FrameEntry{f, frame_timestamp_ns(f, fps)});
  if (auto r = save_rig(dir + "/rig.yaml", rig); !r) return r.error();
  if (auto r = save_frames_csv(dir + "/frames.csv", entries); !r) return r.error();
  return entries;
}

void write_marker_view(std::FILE* csv, const MarkerView& view, SimSummary& summary) {
  std::fprintf(csv, ",%.6f,%.6f,%d", view.center_px.x(), view.center_px.y(),
               view.isolated() ? 1 : 0);
  ++summary.marker_views;
  summary.isolated_views += view.isolated() ? 1 : 0;
  summary.occluded_views += (view.in_front && !view.dropped && view.occluded_area_px > 0.0) ? 1 : 0;
  summary.dropped_views += view.dropped ? 1 : 0;
}

}  // namespace mocap::sim
