// Design: the marker-layout search of a built-in robot (the humanoid's, scene_humanoid.h).
// A robot is described limb by limb in the world at its reference pose (LimbBody: its
// capsules, how many balls and where on its main limb they may sit); the search places
// each body's balls in turn under the rules a lab designs targets by (LayoutRules):
// balls of a target at least min_ball_gap_mm apart and clear of every other limb, the
// inter-marker distances of a target all min_distance_step_mm apart, no triangle of a
// target fitting another triangle of the same target (or itself turned over) within
// self_fit_mm RMS after the best rigid motion (no symmetric target), and none fitting a
// triangle of an earlier target within cross_fit_mm (no copies). Deterministic for a
// seed. Setup code (allocates).
#pragma once

#include <cstdint>
#include <vector>

#include "core/expected.h"
#include "core/types.h"

namespace mocap::sim {

// A limb capsule in the world at the reference pose.
struct LimbCapsule {
  Vec3 a, b;
  double radius_mm;
};

// One body: its limbs (the first carries the balls), how many balls and where on the
// main limb they may sit: a fraction [s_lo, s_hi] of its length and an azimuth interval
// [phi_lo_deg, phi_hi_deg] about its axis (limb_azimuth_frame, scene_build.h).
struct LimbBody {
  const char* name;
  int parent;  // -1: the root
  std::vector<LimbCapsule> limbs;
  int markers;
  double s_lo, s_hi;
  double phi_lo_deg, phi_hi_deg;
  Vec3 frame_rot_deg;  // the body frame's deliberate rotation (z, x, y applied in turn)
};

struct LayoutRules {
  double ball_radius_mm;
  double min_ball_gap_mm;       // centre distance of two balls of a target
  double min_distance_step_mm;  // the inter-marker distances of a target differ by this
  double self_fit_mm;           // no triangle fits one of its own target within this RMS
  double cross_fit_mm;          // nor one of another target within this
  double clearance_mm;          // a ball clears every other limb by this
  std::uint64_t seed;
};

// A ball centre and the root of the post that holds it (inside the limb), world.
struct Mount {
  Vec3 center, post_root;
};

// Every body's mounts, in order; a one-line error naming the body when no layout passes.
Expected<std::vector<std::vector<Mount>>> search_limb_layout(const std::vector<LimbBody>& bodies,
                                                             const LayoutRules& rules);

}  // namespace mocap::sim
