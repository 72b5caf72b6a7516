// Design: see labelled_markers.h. One pass over the found bodies; the residual is taken
// against the body's fitted pose, as in poses.csv's rms_mm.
#include "track/labelled_markers.h"

#include <algorithm>

namespace mocap {

int label_markers(const FrameOutput& out, const TargetSet& targets,
                  LabelledMarkers& labelled) noexcept {
  labelled.count = 0;
  const int bodies = std::min<int>(out.poses.count, static_cast<int>(targets.bodies.size()));
  for (int b = 0; b < bodies; ++b) {
    const BodyPose& pose = out.poses.bodies[static_cast<std::size_t>(b)];
    if (!pose.found) continue;
    const std::vector<Vec3>& model = targets.bodies[static_cast<std::size_t>(b)].markers_body;
    const int markers = std::min<int>(static_cast<int>(model.size()), kMaxMarkers);
    for (int m = 0; m < markers; ++m) {
      const std::int16_t p = pose.point_index_of_marker[static_cast<std::size_t>(m)];
      if (p < 0 || p >= out.points.size()) continue;
      if (labelled.count >= kMaxLabelledMarkers) return labelled.count;
      const Point3& point = out.points[p];
      LabelledMarker& l = labelled.items[static_cast<std::size_t>(labelled.count++)];
      l.body = static_cast<std::int16_t>(b);
      l.marker = static_cast<std::int16_t>(m);
      l.point = p;
      l.cameras = point.blob_index.mask();
      l.X_world_mm = point.X_world;
      l.residual_mm =
          (point.X_world - pose.T_world_body * model[static_cast<std::size_t>(m)]).norm();
    }
  }
  return labelled.count;
}

}  // namespace mocap
