// Design: the rendering and frame-writing set-up shared by the recording writers
// (simulate.cpp: `mocap simulate`, wand_sim.cpp: wand/L-frame recordings) and the
// simulated camera's pre-rendered loop (hal/sim_camera.cpp):
//   StereoRender         : the two cameras' RenderWorkspaces (camera 1's copied from
//                          camera 0's, sharing nothing mutable) and one call that
//                          renders a scene state in both cameras, camera 1 on a second
//                          thread when threads >= 2. Every random draw of the renderer
//                          is keyed by seed, frame and camera, so the images are the
//                          same with one thread or two.
//   begin_recording      : the recording folder (dir, gt/, one image folder per
//                          camera), rig.yaml and frames.csv (frame f at
//                          frame_timestamp_ns(f, fps)).
//   write_marker_view    : one camera's columns u,v,vis of gt/markers.csv and the view
//                          counts of the SimSummary.
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

class StereoRender {
 public:
  // The workspaces of both cameras of `scene`, which must outlive this object.
  static Expected<StereoRender> create(const SimScene& scene, int threads);

  // Renders camera c of `state` into *images[c] (sized by make_camera_image) for
  // c = 0, 1, then calls after(c) on the same thread when given (e.g. to write the
  // image); camera 1 runs on a second thread when threads >= 2. Error: the first
  // failing camera's, "simulate: render: camera <c> failed" or after's error.
  Expected<void> render(const SceneState& state, const std::array<Image*, 2>& images,
                        const std::function<Expected<void>(int camera)>& after = {});

  // What the last render() found in camera c (markers, strays).
  const RenderWorkspace& workspace(int camera) const noexcept {
    return workspaces_[static_cast<std::size_t>(camera)];
  }

 private:
  StereoRender(const SimScene& scene, RenderWorkspace ws, int threads);

  const SimScene* scene_;
  std::array<RenderWorkspace, 2> workspaces_;
  int threads_;
};

// Creates dir, dir/gt and dir/<camera name> for every camera of the rig, writes
// dir/rig.yaml and dir/frames.csv (frames 0..frames-1 at frame_timestamp_ns(f, fps)),
// and returns the frame list.
Expected<std::vector<FrameEntry>> begin_recording(const std::string& dir, const Rig& rig,
                                                  int frames, double fps);

// Appends ",u,v,vis" of one marker view to a gt/markers.csv row and counts the view in
// summary (marker, isolated, occluded and dropped views).
void write_marker_view(std::FILE* csv, const MarkerView& view, SimSummary& summary);

}  // namespace mocap::sim
