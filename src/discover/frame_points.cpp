// Design: see frame_points.h.
#include "discover/frame_points.h"

#include <optional>
#include <vector>

#include "formats/recording.h"
#include "track/frame_processor.h"
#include "track/frame_source.h"

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
  for (const std::string& w : rec->warnings())  // a blob file's torn tail, damaged chunks
    if (cb.warn) cb.warn(w);
  // Detected images or a blob recording's blob lists (track/frame_source.h).
  FrameSource source(*rec, *proc, 1);
  const auto& frames = rec->frames();
  seq.frames.reserve(frames.size());
  for (std::size_t fi = 0; fi < frames.size(); ++fi) {
    const FrameEntry& fe = frames[fi];
    FramePoints fp;
    fp.frame = fe.frame;
    fp.timestamp_ns = fe.timestamp_ns;
    const FrameSource::Result loaded = source.load(fe.frame, out);
    if (loaded.damaged > 0) {  // a damaged frame is skipped (as in `mocap calibrate`), and reported
      if (!first_error) first_error = Error{loaded.problem};
      if (cb.warn) cb.warn(loaded.problem + " (frame " + std::to_string(fe.frame) + " skipped)");
    }
    const auto present = static_cast<std::size_t>(loaded.present);
    if (present < n_cams) ++seq.frames_missing_camera;
    if (present >= static_cast<std::size_t>(kMinCameras)) {  // two cameras triangulate
      ++usable_frames;
      proc->process_blobs(fe.timestamp_ns, out);
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
