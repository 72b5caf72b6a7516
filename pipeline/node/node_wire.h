// Design: the wire format of the camera-node messages (docs/formats.md, "Camera nodes"),
// independent of DDS so that it is unit-tested and fuzzed on its own (tests/fuzz,
// "node_message"). A BlobFrame (node_msgs.idl) is a fixed header plus the frame's blobs
// packed as kBlobRecordBytes-byte little-endian records in a bounded octet sequence:
//   f64 x_px, f64 y_px, f32 area_px, f32 sum_dn, u16 peak_dn, u16 background_dn,
//   i32 x_min, y_min, x_max, y_max, f32 major_axis_px, minor_axis_px, roundness,
//   eccentricity, orientation_rad, u32 flags                       (68 bytes)
// Floats are copied as their IEEE-754 bits, so the central tracker sees the node's
// detector output bit for bit (same angles as one process).
// The decoder trusts nothing it receives: the version, the flags, the names (NUL within
// their bound, printable), blob_count against the bytes present, kMaxBlobsPerMessage and
// the receiving list's capacity, and every value (finite, in range). A message fails as a
// whole with one WireError (counted by the receiver), never partly. Everything here is
// noexcept and allocation-free: the central receiver calls it per message.
#pragma once

#include <cstddef>
#include <cstdint>

#include "core/camera_set.h"
#include "detect/blob.h"

namespace mocap::node {

inline constexpr std::uint16_t kWireVersion = 1;
inline constexpr std::size_t kNameBytes = 64;  // string<63> + NUL (node_msgs.idl)
inline constexpr std::size_t kBlobRecordBytes = 68;
inline constexpr std::uint32_t kMaxBlobsPerMessage = 2048;  // node_msgs.idl's bound / 68
inline constexpr std::size_t kMaxBlobBytes = kMaxBlobsPerMessage * kBlobRecordBytes;

enum WireFlag : std::uint16_t {
  kWireMissing = 1u << 0,      // the camera had no image for this frame (replay)
  kWireEndOfStream = 1u << 1,  // the camera's replay ended: no frame, no more frames
  kWireReplay = 1u << 2,       // capture_ns is a recording's timestamp, not a live clock
};
inline constexpr std::uint16_t kWireKnownFlags = kWireMissing | kWireEndOfStream | kWireReplay;

// The camera's health as the node counts it (lifetime counters).
struct WireHealth {
  std::uint64_t frames = 0;
  std::uint64_t camera_dropped = 0;
  std::uint64_t queue_dropped = 0;
  std::uint64_t detect_overflow = 0;
  std::uint64_t timeouts = 0;
};

// Everything of a BlobFrame but the blob bytes (node_msgs.idl, same fields). Trivially
// copyable: it travels through the node's drop-oldest queue inside WireFrame.
struct WireHeader {
  char node[kNameBytes] = {};
  char camera[kNameBytes] = {};
  std::uint16_t version = kWireVersion;
  std::uint16_t flags = 0;
  std::uint64_t frame_number = 0;
  std::int64_t capture_ns = 0;
  std::int64_t trigger_sent_ns = 0;
  std::int64_t trigger_received_ns = 0;
  std::int64_t sent_ns = 0;
  std::int64_t detected_ns = 0;
  // The node's CLOCK_REALTIME - CLOCK_MONOTONIC: the central maps a live camera's
  // capture_ns onto its own clock through the (PTP-synchronised) CLOCK_REALTIME.
  std::int64_t realtime_offset_ns = 0;
  WireHealth health;
  double background_dn = 0.0;
  double noise_dn = 0.0;
  double threshold_dn = 0.0;
  std::uint32_t blob_count = 0;
};

// One message as the node queues it for its DDS thread (trivially copyable, fixed size:
// it lives in the node's preallocated drop-oldest queues).
struct WireFrame {
  WireHeader header;
  std::uint8_t blobs[kMaxBlobBytes];  // header.blob_count records
};

enum class WireError : std::uint8_t {
  kOk,
  kBadVersion,  // malformed: version != kWireVersion
  kBadFlags,    // malformed: unknown flag bits, or end-of-stream with blobs
  kBadName,     // malformed: a name without NUL in its bound, empty, or not printable
  kBadSize,     // malformed: the bytes are not blob_count records
  kBadValue,    // malformed: a non-finite or out-of-range field
  kOversized,   // blob_count above kMaxBlobsPerMessage or the receiver's capacity
};
const char* to_string(WireError e) noexcept;

// True for a name of 1..kNameBytes-1 printable ASCII characters, NUL-terminated within
// the array (the check every received name passes).
bool valid_name(const char (&name)[kNameBytes]) noexcept;
// Copies `text` (truncated to kNameBytes-1) into `name`, NUL-padded.
void set_name(char (&name)[kNameBytes], const char* text) noexcept;

// Packs blobs [0, count) into `out` (capacity bytes). Returns the records written:
// min(blobs.size(), kMaxBlobsPerMessage, capacity / kBlobRecordBytes).
std::uint32_t encode_blobs(const detect::BlobList& blobs, std::uint8_t* out,
                           std::size_t capacity) noexcept;

// Checks the header (version, flags, names, blob_count bound).
WireError check_header(const WireHeader& h) noexcept;
// Checks the header and decodes its blob_count records from data[0, size) into `out`
// (cleared first; levels set from the header). On any error `out` is left empty.
WireError decode_frame(const WireHeader& h, const std::uint8_t* data, std::size_t size,
                       detect::BlobList& out) noexcept;

}  // namespace mocap::node
