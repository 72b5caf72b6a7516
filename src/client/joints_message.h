// Design: the public, fixed-size message of joint angles that `mocap run` publishes
// for every frame reaching the end of the pipeline, over iceoryx (service "mocap",
// instance "tracker", event "joints": this struct is the payload) and UDP (the spec's
// datagram v1 carries the angles, version 2 also the quality and the rates). Consumers include this
// header only; it depends on nothing but <cstdint> and core/joint_type.h (the project's one joint
// type, installed with it). Trivially copyable, no pointers (iceoryx requirement).
#pragma once

#include <cstdint>

#include "core/joint_type.h"

namespace mocap::client {

inline constexpr std::uint16_t kMaxJoints = 32;

// The joint type of a JointRecord: mocap::JointType (wire values kBall = 0, kHinge = 1).
using JointKind = ::mocap::JointType;

struct JointRecord {
  std::uint16_t index = 0;                // position of the joint in model.yaml
  std::uint8_t type = 0;                  // JointKind
  std::uint8_t valid = 0;                 // 1 when both bodies were found in this frame
  float a[3] = {0.0f, 0.0f, 0.0f};        // radians: hinge (angle, 0, 0); ball XYZ Euler angles
  float q[4] = {1.0f, 0.0f, 0.0f, 0.0f};  // qw, qx, qy, qz of R_parent^T R_child, qw >= 0
};

inline constexpr std::uint32_t kFlagAllBodiesFound = 1u << 0;
// 2027-01: the angles (and their sds and quaternions) are predicted to publish_ns + lead_us
// by the tracker (outputs.*.lead_ms), not measured at capture_ns.
inline constexpr std::uint32_t kFlagPredicted = 1u << 1;

// How a joint's angles were obtained in this frame (2026-12 extension).
enum class SolvedBy : std::uint8_t {
  kNone = 0,   // not valid in this frame
  kPoses = 1,  // from the full poses of both bodies (R_parent^T R_child)
  kChain = 2,  // from the kinematic chain: the parent's pose, the calibrated joint and
               // whatever child markers were seen (1+ for a hinge, 2+ for a ball)
};

// "poses", "chain" or "none" (the solved_by column of angles.csv and mocap echo).
inline constexpr const char* solved_by_name(SolvedBy s) noexcept {
  switch (s) {
    case SolvedBy::kPoses:
      return "poses";
    case SolvedBy::kChain:
      return "chain";
    case SolvedBy::kNone:
      break;
  }
  return "none";
}

// Per-joint quality of the angles (2026-12 extension, not in the UDP datagram v1).
struct JointQuality {
  std::uint8_t solved_by = 0;  // SolvedBy
  std::uint8_t reserved[3] = {0, 0, 0};
  float sd_rad[3] = {0.0f, 0.0f, 0.0f};  // standard deviation of a0, a1, a2 (radians)
};

// Per-joint rates (2027-01 extension): the live tracker's causal rates of a0..a2 and their
// standard deviations (kinematics/joint_rates.h; a hinge uses index 0).
struct JointRates {
  std::uint8_t valid = 0;  // 1: rates known (the joint is valid and its filter warmed up)
  std::uint8_t reserved[3] = {0, 0, 0};
  float rate_rad_s[3] = {0.0f, 0.0f, 0.0f};
  float sd_rad_s[3] = {0.0f, 0.0f, 0.0f};
};

struct JointsMessage {
  std::uint64_t sequence = 0;     // counts every triggered frame: a gap means drops
  std::int64_t capture_ns = 0;    // CLOCK_MONOTONIC, trigger of this frame
  std::int64_t publish_ns = 0;    // CLOCK_MONOTONIC, when published
  std::uint32_t flags = 0;        // kFlagAllBodiesFound, kFlagPredicted
  std::uint16_t joint_count = 0;  // records used in `joints`
  std::uint16_t lead_us = 0;      // kFlagPredicted: the lead (us) the state is predicted by
                                  // past publish_ns (<= 50000); else 0 (was `reserved`)
  JointRecord joints[kMaxJoints];
  // Appended by the 2026-12 extension (the layout above is unchanged): quality[j] belongs
  // to joints[j].
  JointQuality quality[kMaxJoints];
  // Appended by the 2027-01 extension: rates[j] belongs to joints[j].
  JointRates rates[kMaxJoints];
};

static_assert(sizeof(JointRecord) == 32, "the UDP joint record is 32 bytes");
static_assert(sizeof(JointQuality) == 16, "JointQuality is 16 bytes");
static_assert(sizeof(JointRates) == 28, "JointRates is 28 bytes");

}  // namespace mocap::client
