// Design: the one record of a frame's whole result that the publish stage hands to every
// output sink (UDP, iceoryx, ROS 2, Foxglove, ...): the joint angles with validity and
// quality (the public client::JointsMessage), the body poses, the labelled markers, the
// 3D points and each camera's blobs with what they were used for (the live view's aiming
// overlay). Fixed capacity and trivially copyable, so that it lives in preallocated
// publish slots and can be copied into the bounded drop-oldest queue of a slow sink
// without allocation. Each sink encodes what it needs; names (bodies, joints, cameras)
// are given to sinks once at setup (OutputContext in output_sink.h), not per frame.
// Units: millimetres, radians, world frame; a pose maps body to world (X_world = R X_body + t).
#pragma once

#include <array>
#include <cstdint>
#include <type_traits>

#include "client/joints_message.h"
#include "core/camera_set.h"

namespace mocap::publish {

// The compiled capacities of one frame's result (docs/formats.md, "Capacities", with their
// memory: sizeof(FrameResult) is 57.6 KiB). The builder (pipeline/
// frame_result_builder.cpp) asserts that they hold everything the tracker produces.
inline constexpr int kMaxResultBodies = 32;            // = identify's kMaxBodies
inline constexpr int kMaxResultMarkers = 512;          // labelled markers per frame (32 x 16)
inline constexpr int kMaxResultPoints = 512;           // 3D points per frame (= kMaxPoints)
inline constexpr int kMaxResultCameras = kMaxCameras;  // cameras with blobs
inline constexpr int kMaxResultBlobs = 256;  // blobs per camera (= stereo max_points_per_camera)
// The blobs of all cameras together: 8 cameras keep kMaxResultBlobs each; a larger rig
// shares them (result_blobs_per_camera), so the result does not grow with kMaxCameras.
inline constexpr int kMaxResultBlobTotal = 8 * kMaxResultBlobs;
// Blobs kept per camera of a rig of `cameras` cameras (256 up to 8 cameras, 64 at 32).
constexpr int result_blobs_per_camera(int cameras) noexcept {
  return cameras <= 8 ? kMaxResultBlobs : kMaxResultBlobTotal / cameras;
}

struct ResultBody {
  std::uint8_t found = 0;           // 1: the body was found in this frame
  std::uint8_t markers = 0;         // markers matched
  std::uint8_t velocity_valid = 0;  // 1: v_world_mm_s and w_world_rad_s are estimated
  std::uint8_t reserved = 0;
  float rms_mm = 0.0f;                                       // residual of the fit
  std::array<double, 4> q_world_body{{1.0, 0.0, 0.0, 0.0}};  // qw, qx, qy, qz, qw >= 0
  std::array<double, 3> t_world_body_mm{{0.0, 0.0, 0.0}};
  std::array<float, 3> v_world_mm_s{{0, 0, 0}};   // velocity of the body origin, world frame
  std::array<float, 3> w_world_rad_s{{0, 0, 0}};  // angular velocity, world frame
};

struct ResultMarker {
  std::uint8_t body = 0;    // index in targets.yaml
  std::uint8_t marker = 0;  // index in that body's target
  std::uint8_t reserved[2] = {0, 0};
  float residual_mm = 0.0f;                    // |measured - posed model marker|
  std::array<float, 3> X_world_mm{{0, 0, 0}};  // the measured point
};

struct ResultPoint {
  std::array<float, 3> X_world_mm{{0, 0, 0}};
  float reproj_px = 0.0f;
  std::uint8_t cameras = 0;   // how many cameras saw the point
  std::uint8_t labelled = 0;  // 1: a body claimed it (it is one of the labelled markers)
  std::uint8_t reserved[2] = {0, 0};
};
static_assert(sizeof(ResultPoint) == 20, "ResultPoint keeps its size (labelled was reserved)");

// What a blob became in this frame.
enum class BlobUse : std::uint8_t {
  kUnused = 0,  // no 3D point (seen by one camera only, a stray, or rejected by stereo)
  kPoint = 1,   // part of a triangulated 3D point that no body claimed
  kMarker = 2,  // part of a labelled marker of a body (body, marker set)
};

struct ResultBlob {
  float x_px = 0.0f;         // sub-pixel centroid, image pixels (column)
  float y_px = 0.0f;         // (row)
  float diameter_px = 0.0f;  // diameter of the disc of the blob's area
  std::uint8_t use = 0;      // BlobUse
  std::uint8_t body = 0;     // kMarker: index in targets.yaml
  std::uint8_t marker = 0;   // kMarker: index in that body's target
  std::uint8_t reserved = 0;
};

// A camera's blobs are FrameResult::blobs[first, first + count) (FrameResult::blobs_of);
// a camera with more keeps its first result_blobs_per_camera(camera_count).
struct CameraBlobs {
  std::int32_t count = 0;
  std::uint8_t present = 0;  // 1: the camera's frame arrived
  std::uint8_t reserved[3] = {0, 0, 0};
  std::int32_t first = 0;
};

struct FrameResult {
  client::JointsMessage joints;  // sequence, capture/publish time, flags, angles + quality
  std::int32_t body_count = 0;
  std::int32_t marker_count = 0;
  std::int32_t point_count = 0;
  std::array<ResultBody, kMaxResultBodies> bodies{};
  std::array<ResultMarker, kMaxResultMarkers> markers{};
  std::array<ResultPoint, kMaxResultPoints> points{};
  std::int32_t camera_count = 0;  // the rig's cameras, in rig order
  std::array<CameraBlobs, kMaxResultCameras> cameras{};
  std::array<ResultBlob, kMaxResultBlobTotal> blobs{};

  // Camera c's blobs ([0, cameras[c].count)); c < camera_count.
  const ResultBlob* blobs_of(int c) const noexcept {
    return blobs.data() + cameras[static_cast<std::size_t>(c)].first;
  }
  ResultBlob* blobs_of(int c) noexcept {
    return blobs.data() + cameras[static_cast<std::size_t>(c)].first;
  }
};

static_assert(std::is_trivially_copyable_v<FrameResult>, "FrameResult lives in slots");

}  // namespace mocap::publish
