// Design: the live view's aiming overlay: per rig camera, a small grey-level image of
// where that camera sees blobs and what each became in the frame, drawn from the blob
// lists of the frame result (no camera image crosses the output seam). Sent on
// /<camera>/blobs as foxglove.RawImage ("mono8") at a low rate (kBlobOverlayPeriodNs),
// only while a viewer subscribes. Each blob is a filled disc (at least 1 px) at its
// centroid, scaled by 1/kBlobOverlayScale from the camera's pixels, with the grey level
// saying what it became:
//   255  a labelled marker of a body,  150  a 3D point no body claimed,
//    70  unused (one camera only, a stray, rejected by stereo);
// a dim 1-px border (40) outlines the image so that an empty view is still visible.
// Runs on the Foxglove sink's worker thread (may allocate).
#pragma once

#include <cstdint>
#include <string>
#include <string_view>

#include "pipeline/foxglove/scene.h"
#include "pipeline/publish/frame_result.h"

namespace mocap::foxglove {

inline constexpr int kBlobOverlayScale = 4;                      // camera px per overlay px
inline constexpr std::int64_t kBlobOverlayPeriodNs = 200000000;  // 5 images/s per camera
inline constexpr std::uint8_t kGreyMarker = 255;
inline constexpr std::uint8_t kGreyPoint = 150;
inline constexpr std::uint8_t kGreyUnused = 70;
inline constexpr std::uint8_t kGreyBorder = 40;

// The overlay of camera `camera` (index into scene.cameras and frame.cameras) as the JSON
// of one foxglove.RawImage message; empty when the scene has no such camera.
std::string encode_blob_overlay(const FoxgloveScene& scene, const publish::FrameResult& frame,
                                int camera, std::int64_t stamp_ns);

// Standard base64 (RFC 4648, with padding), as Foxglove's JSON encoding wants bytes.
std::string base64(std::string_view bytes);

}  // namespace mocap::foxglove
