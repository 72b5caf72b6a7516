// Design: from the tracker's FrameOutput (src/track) to the one record every output sink
// receives (publish::FrameResult): the public JointsMessage (angles with validity and
// quality), the body poses, the labelled markers (each matched model marker with the
// measured point and its residual to the posed model marker), the 3D points (the
// reported ones, as points.csv, with reprojection error and camera count) and each
// camera's blobs with what they became. Runs on the identify thread once per frame:
// noexcept, allocation-free; anything beyond FrameResult's fixed capacities is left out.
// The targets give the body and marker order and the model marker positions.
// Capacities: FrameResult holds every body (kMaxBodies), labelled marker
// (kMaxLabelledMarkers) and point (kMaxPoints) the tracker can produce, and every joint
// (client::kMaxJoints >= the chain solver's bound) — static_asserts in the .cpp; only a
// camera's blobs beyond kMaxResultBlobs are left out.
#pragma once

#include <cstdint>

#include "client/joints_message.h"
#include "formats/targets_yaml.h"
#include "pipeline/publish/frame_result.h"
#include "track/frame_processor.h"
#include "track/labelled_markers.h"

namespace mocap::pipeline {

// Fills `msg` from the frame's joint angles (sequence, capture_ns, flags, joints,
// quality); publish_ns is set by the publish stage.
void make_joints_message(std::uint64_t sequence, std::int64_t capture_ns, const FrameOutput& out,
                         client::JointsMessage& msg) noexcept;

// Fills all of `result` (joints via make_joints_message); publish_ns is left 0.
// `labelled` is the caller's workspace (preallocated: too big for a real-time stack).
void make_frame_result(std::uint64_t sequence, std::int64_t capture_ns, const TargetSet& targets,
                       const FrameOutput& out, LabelledMarkers& labelled,
                       publish::FrameResult& result) noexcept;

}  // namespace mocap::pipeline
