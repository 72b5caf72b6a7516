// Design: see frame_writer.h. The second render thread is started per call and joined
// before it returns, so a MultiRender is used by one thread at a time.
#include "sim/frame_writer.h"

#include <algorithm>
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

Expected<MultiRender> MultiRender::create(const SimScene& scene, int threads) {
  auto ws = RenderWorkspace::create(scene);
  if (!ws) return ws.error();
  return MultiRender(scene, std::move(ws).value(), threads);
}

MultiRender::MultiRender(const SimScene& scene, RenderWorkspace ws, int threads) : scene_(&scene) {
  const std::size_t n = scene.rig.cameras.size();
  views_.resize(n);
  for (CameraViews& v : views_) {
    v.markers.resize(ws.markers.size());
    v.strays.resize(ws.strays.size());
  }
  image_ptrs_.resize(n);
  // A second workspace only when a second thread will use it; it copies the read-only
  // lattices instead of recomputing them.
  if (threads >= 2 && n >= 2) workspaces_.push_back(ws);
  workspaces_.insert(workspaces_.begin(), std::move(ws));
}

Expected<void> MultiRender::render(const SceneState& state, std::vector<Image>& images,
                                   const std::function<Expected<void>(int camera)>& after) {
  if (images.size() != views_.size())
    return make_error("simulate", "render", "one image per camera is needed");
  for (std::size_t c = 0; c < images.size(); ++c) image_ptrs_[c] = &images[c];
  return render_all(state, image_ptrs_.data(), after);
}

Expected<void> MultiRender::render(const SceneState& state, const std::array<Image*, 2>& images,
                                   const std::function<Expected<void>(int camera)>& after) {
  if (views_.size() != 2) return make_error("simulate", "render", "the rig has not 2 cameras");
  return render_all(state, images.data(), after);
}

Expected<void> MultiRender::render_all(const SceneState& state, Image* const* images,
                                       const std::function<Expected<void>(int camera)>& after) {
  const int n = camera_count();
  const int threads = static_cast<int>(workspaces_.size());
  // Thread t renders the cameras c = t, t + threads, ...; its first error is kept.
  std::array<Expected<void>, 2> results;
  auto job = [&](int t) {
    RenderWorkspace& ws = workspaces_[static_cast<std::size_t>(t)];
    for (int c = t; c < n; c += threads) {
      const auto uc = static_cast<std::size_t>(c);
      if (!sim::render(*scene_, state, c, ws, *images[uc])) {
        results[static_cast<std::size_t>(t)] =
            make_error("simulate", "render", "camera " + std::to_string(c) + " failed");
        return;
      }
      CameraViews& v = views_[uc];
      std::copy(ws.markers.begin(), ws.markers.end(), v.markers.begin());
      std::copy(ws.strays.begin(), ws.strays.begin() + ws.stray_count, v.strays.begin());
      v.stray_count = ws.stray_count;
      if (after) {
        if (auto r = after(c); !r) {
          results[static_cast<std::size_t>(t)] = r;
          return;
        }
      }
    }
  };
  if (threads >= 2) {
    std::thread t1(job, 1);
    job(0);
    t1.join();
  } else {
    job(0);
  }
  for (Expected<void>& r : results) {
    if (!r) return r;
  }
  return {};
}

std::vector<Image> make_camera_images(const SimScene& scene) {
  std::vector<Image> images;
  images.reserve(scene.rig.cameras.size());
  for (std::size_t c = 0; c < scene.rig.cameras.size(); ++c)
    images.push_back(make_camera_image(scene, static_cast<int>(c)));
  return images;
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

namespace mocap::sim {

std::string markers_csv_camera_columns(int cameras, bool extra) {
  std::string h;
  for (int k = 0; k < cameras; ++k) {
    const std::string K = std::to_string(k);
    h += (k ? ",u" : "u") + K + ",v" + K + ",vis" + K;
  }
  for (int k = 0; extra && k < cameras; ++k) {
    const std::string K = std::to_string(k);
    h += ",frac" + K + ",merged" + K + ",dropped" + K;
  }
  return h;
}

}  // namespace mocap::sim
