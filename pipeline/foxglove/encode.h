// Design: the encoders of the live view's channels, from one frame's result
// (publish::FrameResult) and the immutable scene (scene.h) to the JSON text of one
// message. They run on the Foxglove sink's worker thread, never on the real-time
// threads, and may allocate. Units and frames: FrameResult is in millimetres in the
// world frame; Foxglove uses metres, so every position is divided by 1000 and every
// body pose becomes a transform world_frame ("mocap") -> body name.
//   /tf       foxglove.FrameTransforms: one transform per body found in the frame.
//   /markers  foxglove.SceneUpdate: entity "points" (every triangulated point, small grey
//             spheres), "markers" (labelled markers, spheres coloured by body), "bodies"
//             (body name labels), "joints" (joint centres as spheres, hinge axes as
//             arrows, of joints whose parent body was found).
//   /joints   mocap.JointAngles: name, type, valid, angles (rad), solved_by, sd (rad).
//   /<camera>/blobs  foxglove.RawImage, one per rig camera (2..32), at a low rate: the blob
//             overlay for aiming (blob_overlay.h).
// Timestamps: stamp_ns is the capture time on the wall clock (CLOCK_REALTIME, ns).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "pipeline/foxglove/protocol.h"
#include "pipeline/foxglove/scene.h"
#include "pipeline/publish/frame_result.h"

namespace mocap::foxglove {

inline constexpr std::uint32_t kChannelTf = 1;
inline constexpr std::uint32_t kChannelMarkers = 2;
inline constexpr std::uint32_t kChannelJoints = 3;
inline constexpr std::uint32_t kChannelBodies = 4;
inline constexpr std::uint32_t kChannelBlobsFirst = 16;  // + camera index

// The advertised channels, ids as above (a blob channel per camera of the scene).
std::vector<ChannelInfo> live_view_channels(const FoxgloveScene& scene);

std::string encode_frame_transforms(const FoxgloveScene& scene, const publish::FrameResult& frame,
                                    std::int64_t stamp_ns);
std::string encode_scene_update(const FoxgloveScene& scene, const publish::FrameResult& frame,
                                std::int64_t stamp_ns);
// /bodies (mocap.BodyStates): every body of the targets with its quality (markers used,
// fit residual), pose and, when known, velocities; found or not.
std::string encode_body_states(const FoxgloveScene& scene, const publish::FrameResult& frame,
                               std::int64_t stamp_ns);
std::string encode_joint_angles(const FoxgloveScene& scene, const publish::FrameResult& frame,
                                std::int64_t stamp_ns);

}  // namespace mocap::foxglove
