// Design: step 4 of `mocap discover`: the joint topology from the body poses.
// Every pair of bodies seen together in at least linear.min_poses frames (at most
// 400, evenly subsampled) gets the Eq. 2 system of src/kinematics on its relative
// poses. Its normalised singular values decide (docs/kinematics.md):
//  - s5 < min_motion_deg: too little relative motion: no joint can be determined
//    (a note, reported when a body stays unconnected);
//  - s6 / s5 <= max_hinge_off_axis_ratio: a hinge (rank-5), scored by the hinge fit's
//    residual; otherwise a ball joint when s6 >= min_motion_deg, scored by the ball
//    fit's residual;
//  - a residual above max_joint_residual_mm: the bodies are not joined directly.
// The tree: Kruskal's minimum spanning forest over the candidates by residual (the
// most consistent joints first). Root of each tree: the body that moves least in the
// world (smallest RMS displacement); parents are nearer the root. Body order: trees
// by size, each root first then breadth-first; unjoined bodies last.
#pragma once

#include <string>
#include <vector>

#include "discover/body_builder.h"
#include "formats/joints_yaml.h"

namespace mocap::discover {

struct JointEdge {
  int parent = 0;  // indices into the discovered bodies
  int child = 0;
  JointType type = JointType::kBall;
  double residual_mm = 0.0;           // linear fit residual (rms, per pose)
  Vec3 center_parent = Vec3::Zero();  // the linear estimate's centre (hinge: a point on the axis)
  Vec3 axis_parent = Vec3::UnitZ();   // hinge axis (unit), parent frame
  kinematics::LinearDiagnostics diagnostics;
};

struct TopologyResult {
  std::vector<int> body_order;    // discovered body indices in output order
  std::vector<JointEdge> joints;  // parents before children
  std::vector<std::string> notes;
  std::vector<std::pair<int, int>> low_motion_pairs;  // (a, b) with too little motion
};

// The joint candidate between parent P and child C (the test above); false when the pair
// is none (too few common frames, too little motion, residual too large).
bool joint_candidate(const DiscoveredBody& P, const DiscoveredBody& C,
                     const DiscoverOptions& options, JointEdge& edge);

TopologyResult infer_topology(const std::vector<DiscoveredBody>& bodies,
                              const DiscoverOptions& options);

}  // namespace mocap::discover
