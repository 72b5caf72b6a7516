// Design: what the labelled-trajectory exports (C3D, TRC) share: the layout fixed at open
// (one trajectory per model marker, labelled `BODY_mN`, the rate and the frame count of
// the recording) and one sample per trajectory and frame. Writers stream: the header is
// written at open from the layout, then one frame at a time, so no whole-recording
// buffer is held. write_frame() is noexcept and allocation-free (buffers sized at open);
// a write failure is remembered and reported by close() as a one-line error naming the
// file (and write_frame returns false from then on, so callers may stop early).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "core/types.h"

namespace mocap {

struct TrajectoryLayout {
  std::vector<std::string> labels;        // one per trajectory, e.g. "torso_m0"
  std::vector<std::string> descriptions;  // empty, or one per label
  double rate_hz = 0.0;                   // frames per second (> 0)
  std::int64_t frame_count = 0;           // frames that will be written (>= 1)
  std::int64_t first_frame = 1;           // number of the first frame (1-based)
};

struct TrajectorySample {
  bool valid = false;        // false: the marker was not seen in this frame
  std::uint8_t cameras = 0;  // bit c: camera c contributed (C3D camera mask, 7 bits)
  Vec3 X_mm = Vec3::Zero();  // world frame, millimetres
  double residual_mm = 0.0;  // distance to the posed model marker
};

}  // namespace mocap
