// Design: the rendering and frame-writing set-up shared by the recording writers
// (simulate.cpp: `mocap simulate`, wand_sim.cpp: wand/L-frame recordings) and the
// simulated camera's pre-rendered loop (hal/sim_camera.cpp):
//   MultiRender          : renders a scene state in every camera of the rig (2..32) with
//                          one RenderWorkspace per rendering thread (the second copied
//                          from the first, sharing nothing mutable): with threads >= 2
//                          the even cameras on the calling thread, the odd ones on a
//                          second thread. After each camera its results (marker views,
//                          strays) are copied into that camera's preallocated
//                          CameraViews, so a frame's results of every camera are there
//                          at the end (no allocation per frame). Every random draw of
//                          the renderer is keyed by seed, frame and camera, so the
//                          images are the same with one thread or two. StereoRender
//                          is its older name (the sim camera backend uses it).
//   begin_recording      : the recording folder (dir, gt/, one image folder per
//                          camera), rig.yaml and frames.csv (frame f at
//                          frame_timestamp_ns(f, fps)).
//   write_marker_view    : one camera's columns u,v,vis of gt/markers.csv and the view
//                          counts of the SimSummary; markers_csv_header names the
//                          per-camera columns uK,vK,visK for every camera K.
// Setup-style code: errors are one line, "simulate: key: problem" or "<path>: problem".
#pragma once

#include <array>
#include <cstdio>
#include <functional>
#include <string>
#include <vector>

#include "core/expected.h"
#include "core/image.h"
#include "formats/recording.h"
#include "sim/render.h"
#include "sim/scene.h"
#include "sim/simulate.h"

namespace mocap::sim {

// What render() found in one camera: a copy of the workspace's results.
struct CameraViews {
  std::vector<MarkerView> markers;  // one per scene marker
  std::vector<StrayView> strays;    // [0, stray_count) valid
  int stray_count = 0;
};

class MultiRender {
 public:
  // The workspaces for rendering every camera of `scene`, which must outlive this object.
  static Expected<MultiRender> create(const SimScene& scene, int threads);

  int camera_count() const noexcept { return static_cast<int>(views_.size()); }

  // Renders camera c of `state` into images[c] (sized by make_camera_image) for every
  // camera c, then calls after(c) on the same thread when given (e.g. to write the
  // image); with threads >= 2 the odd cameras run on a second thread. images.size()
  // must be camera_count(). Error: the first failing camera's, "simulate: render:
  // camera <c> failed" or after's error.
  Expected<void> render(const SceneState& state, std::vector<Image>& images,
                        const std::function<Expected<void>(int camera)>& after = {});

  // The same for a 2-camera scene with the images given by pointer.
  Expected<void> render(const SceneState& state, const std::array<Image*, 2>& images,
                        const std::function<Expected<void>(int camera)>& after = {});

  // What the last render() found in camera c (markers, strays).
  const CameraViews& views(int camera) const noexcept {
    return views_[static_cast<std::size_t>(camera)];
  }

 private:
  MultiRender(const SimScene& scene, RenderWorkspace ws, int threads);
  Expected<void> render_all(const SceneState& state, Image* const* images,
                            const std::function<Expected<void>(int camera)>& after);

  const SimScene* scene_;
  std::vector<RenderWorkspace> workspaces_;  // one per rendering thread (1 or 2)
  std::vector<CameraViews> views_;           // one per camera
  std::vector<Image*> image_ptrs_;           // scratch of render(vector), sized at setup
};

using StereoRender = MultiRender;  // the older name

// All cameras' images of a scene (setup; allocates).
std::vector<Image> make_camera_images(const SimScene& scene);

// Creates dir, dir/gt and dir/<camera name> for every camera of the rig, writes
// dir/rig.yaml and dir/frames.csv (frames 0..frames-1 at frame_timestamp_ns(f, fps)),
// and returns the frame list.
Expected<std::vector<FrameEntry>> begin_recording(const std::string& dir, const Rig& rig,
                                                  int frames, double fps);

// Appends ",u,v,vis" of one marker view to a gt/markers.csv row and counts the view in
// summary (marker, isolated, occluded and dropped views).
void write_marker_view(std::FILE* csv, const MarkerView& view, SimSummary& summary);

// "uK,vK,visK" for K = 0..cameras-1, joined by commas (gt/markers.csv); with
// `extra` also ",fracK,mergedK,droppedK" for every camera after them. For 2 cameras:
// "u0,v0,vis0,u1,v1,vis1" (+ ",frac0,merged0,dropped0,frac1,merged1,dropped1").
std::string markers_csv_camera_columns(int cameras, bool extra);

}  // namespace mocap::sim
