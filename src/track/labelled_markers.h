// Design: the labelled markers of one frame, built in ONE place from the frame's output
// (FrameOutput) so that every consumer sees the same list: markers.csv, the C3D and TRC
// exports of `mocap track`, and the live sinks (FrameResult::markers). A labelled marker
// is a measured 3D point that identification assigned to a model marker of a found body
// (BodyPose::point_index_of_marker); its residual is |X_measured - T_world_body *
// X_body_model|. When kinematic-chain tracking later labels markers of bodies that are not
// found on their own, it extends label_markers() and every consumer follows.
// Hot-path safe: fixed capacity (kMaxBodies x kMaxMarkers), noexcept, no allocation.
#pragma once

#include <array>
#include <cstdint>

#include "core/types.h"
#include "formats/targets_yaml.h"
#include "identify/identify_types.h"
#include "track/frame_processor.h"

namespace mocap {

// Every marker of every body (32 x 16 = 512; a labelled marker is a distinct point, so
// this also equals kMaxPoints). ~20 KiB: callers keep a LabelledMarkers off the stack.
inline constexpr int kMaxLabelledMarkers = kMaxBodies * kMaxMarkers;

struct LabelledMarker {
  std::int16_t body = 0;           // index in targets.yaml
  std::int16_t marker = 0;         // index in that body's target (targets.yaml order)
  std::int16_t point = -1;         // index in FrameOutput::points
  CameraMask cameras = 0;          // bit c set: camera c saw the point
  Vec3 X_world_mm = Vec3::Zero();  // the measured point, world frame
  double residual_mm = 0.0;        // |X_world_mm - T_world_body * model marker|
};

struct LabelledMarkers {
  int count = 0;
  std::array<LabelledMarker, kMaxLabelledMarkers> items{};
};

// Fills `labelled` with the frame's labelled markers, ordered by body, then marker index.
// Entries whose point index is outside the frame's points are skipped (and not counted
// as labelled). Returns the number of markers written.
int label_markers(const FrameOutput& out, const TargetSet& targets,
                  LabelledMarkers& labelled) noexcept;

}  // namespace mocap
