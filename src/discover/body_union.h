// Design: the last merge of `mocap discover` (docs/discover.md, step 5b): one body built
// as two. When occlusions cut every track of a limb between two windows and neither
// window's target can be identified in the other, the body builder leaves two bodies,
// both with a joint to the same parent at the same place. Two bodies with joint
// candidates (topology.h joint_candidate) to one body P that share one centre (ball: the
// centres; hinge: the axis lines; P: the tree parent of either first, then every other
// body) and whose relative pose stays constant wherever both are posed are one body: two limbs
// cannot hang at one joint centre and move as one without being one. The tolerances
// follow from the noise (discover_types.h): centres within 4 fit tolerances; a relative
// pose constant within 6 sqrt(2) fit tolerances over the bodies' radius (rotation) and
// 6 sqrt(2) fit tolerances (translation) in all but 5 % of at least
// min_covisible_frames() frames.
#pragma once

#include <utility>
#include <vector>

#include "discover/body_builder.h"
#include "discover/topology.h"

namespace mocap::discover {

// Pairs (keep, absorb) of discovered bodies that are one body by the rule above; each
// body appears in at most one pair.
std::vector<std::pair<int, int>> find_split_bodies(const std::vector<DiscoveredBody>& bodies,
                                                   const TopologyResult& topology,
                                                   const DiscoverOptions& options);

// True when B keeps one pose relative to A (T_ab: B's frame in A's) in the frames where
// both are posed, within the tolerances above (at least min_covisible_frames() frames).
bool constant_relative_pose(const DiscoveredBody& A, const DiscoveredBody& B,
                            const DiscoverOptions& options, Iso3& T_ab);

// The bodies with every pair merged: B's markers mapped into A's frame (a marker within a
// quarter diameter of one of A's is that marker), A posed where only B was, B removed.
std::vector<DiscoveredBody> merge_bodies(std::vector<DiscoveredBody> bodies,
                                         const std::vector<std::pair<int, int>>& pairs,
                                         const DiscoverOptions& options);

}  // namespace mocap::discover
