// Design: see frame_points.h.
#include "discover/frame_points.h"

#include <array>
#include <optional>
#include <span>
#include <vector>

#include "formats/recording.h"
#include "track/frame_processor.h"

namespace mocap::discover {

Expected<PointSequence> triangulate_recording(const std::string& recording_dir,
                                              const PointsProgress& cb) {
  auto rec = Recording::open(recording_dir);
  if (!rec) return rec.error();
  const Rig& rig = rec->rig();
  if (rig.cameras.size() < static_cast<std::size_t>(kMinCameras))
    return Error{recording_dir + "/rig.yaml: discover needs two cameras, the rig has " +
                 std::to_string(rig.cameras.size())};
  // The tracker's own stages (default TrackerConfig: round blobs only) over every camera
  // of the rig, without targets: nothing is identified, the 3D points are the result.
  auto proc = FrameProcessor::create(rig, TargetSet{}, nullptr, TrackerConfig{});
  if (!proc) return Error{recording_dir + "/rig.yaml: " + proc.error().message};
  FrameOutput out = proc->make_output();
  const std::size_t n_cams = rig.cameras.size();

  PointSequence seq;
  std::optional<Error> first_error;
  std::size_t usable_frames = 0;
  std::vector<Image> images(n_cams);
  std::array<ImageView, kMaxCameras> image_views{};
  std::array<const ImageView*, kMaxCameras> views{};
  const auto& frames = rec->frames();
  seq.frames.reserve(frames.size());
  for (std::size_t fi = 0; fi < frames.size(); ++fi) {
    const FrameEntry& fe = frames[fi];
    FramePoints fp;
    fp.frame = fe.frame;
    fp.timestamp_ns = fe.timestamp_ns;
    std::size_t present = 0;
    for (std::size_t c = 0; c < n_cams; ++c) {
      views[c] = nullptr;
      auto loaded = rec->load_frame(static_cast<int>(c), fe.frame, images[c]);
      if (!loaded) {  // a damaged frame is skipped (as in `mocap calibrate`), and reported
        if (!first_error) first_error = loaded.error();
        if (cb.warn) {
          cb.warn(loaded.error().message + " (frame " + std::to_string(fe.frame) + ", camera " +
                  rig.cameras[c].name + " skipped)");
        }
        continue;
      }
      if (*loaded != FrameLoad::kOk) continue;
      image_views[c] = images[c].view();
      views[c] = &image_views[c];
      ++present;
    }
    if (present < n_cams) ++seq.frames_missing_camera;
    if (present >= static_cast<std::size_t>(kMinCameras)) {  // two cameras triangulate
      ++usable_frames;
      proc->process(std::span<const ImageView* const>(views.data(), n_cams), fe.timestamp_ns, out);
      for (int i = 0; i < out.points.size(); ++i) {
        const Point3& p = out.points[i];
        // Whole-marker views only: with three or more cameras the tracker has already
        // refitted a point from its whole views when two or more remain (a flagged or
        // misshapen view left out); otherwise the point is partial and left out here.
        const bool keep = !p.ambiguous && !proc->point_partial(i);
        if (keep)
          fp.X_world_mm.push_back(p.X_world);
        else
          ++seq.points_dropped;
      }
    }
    seq.frames.push_back(std::move(fp));
    if (cb.progress)
      cb.progress(static_cast<std::int64_t>(fi + 1), static_cast<std::int64_t>(frames.size()));
  }
  if (usable_frames == 0 && first_error) return *first_error;
  return seq;
}

}  // namespace mocap::discover
