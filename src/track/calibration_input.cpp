#include "track/calibration_input.h"

#include "formats/recording.h"
#include "track/frame_source.h"

namespace mocap {

Expected<CollectedCalibration> collect_calibration_input(const std::string& recording_dir,
                                                         const TargetSet& targets,
                                                         const CalibrationCollectOptions& opt) {
  auto rec = Recording::open(recording_dir);
  if (!rec) return rec.error();
  auto proc = FrameProcessor::create(rec->rig(), targets, nullptr, opt.config);
  if (!proc) return proc.error();

  CollectedCalibration result;
  FrameOutput out = proc->make_output();
  for (const std::string& w : rec->warnings())
    if (opt.warn) opt.warn(w);
  FrameSource source(*rec, *proc, 1);
  const auto& frames = rec->frames();
  for (std::size_t fi = 0; fi < frames.size(); ++fi) {
    const FrameEntry& fe = frames[fi];
    const FrameSource::Result loaded = source.process(fe, out);
    if (loaded.damaged > 0 && opt.warn)
      opt.warn(loaded.problem + " (frame " + std::to_string(fe.frame) + " skipped)");
    ++result.frames;

    kinematics::CalibrationFrame frame;
    frame.bodies.resize(targets.bodies.size());
    int found = 0;
    for (std::size_t b = 0; b < targets.bodies.size(); ++b) {
      const BodyPose& pose = out.poses.bodies[b];
      kinematics::BodyObservation& obs = frame.bodies[b];
      obs.found = pose.found;
      if (!pose.found) continue;
      ++found;
      obs.T_world_body = pose.T_world_body;
      // The refinement sees the markers the pose was fitted on: while at least 3 whole
      // markers are matched, the partial ones (centroid biased by a partly hidden image,
      // kept matched by identification) are left out, as in the identifier's fit.
      const std::size_t nk = targets.bodies[b].markers_body.size();
      auto index_of = [&](std::size_t k) -> int {
        const std::int16_t idx = pose.point_index_of_marker[k];
        return (idx < 0 || idx >= out.points.size()) ? -1 : idx;
      };
      int whole = 0;
      for (std::size_t k = 0; k < nk; ++k)
        whole += (index_of(k) >= 0 && !proc->point_partial(index_of(k))) ? 1 : 0;
      for (std::size_t k = 0; k < nk; ++k) {
        const int idx = index_of(k);
        if (idx < 0 || (whole >= 3 && proc->point_partial(idx))) continue;
        obs.markers.push_back({static_cast<int>(k), out.points[idx].X_world});
      }
    }
    if (found == static_cast<int>(targets.bodies.size())) ++result.frames_all_bodies;
    result.input.frames.push_back(std::move(frame));
    if (opt.progress)
      opt.progress(static_cast<std::int64_t>(fi + 1), static_cast<std::int64_t>(frames.size()));
  }
  return result;
}

}  // namespace mocap
