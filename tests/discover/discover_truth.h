// Design: compares a discover result with the simulator's ground truth (test and
// acceptance-measurement helper). Frames are aligned through the poses: for every frame
// in which a discovered body was found, its markers T_world_body * m are matched to the
// true markers of that frame (gt/poses.csv + the true targets.yaml) within 3 mm; a
// discovered body maps to the true body most of its marker matches fall on. Joint
// parameters are compared in world terms at every frame with both poses: the ball
// centre (and a hinge's point, as its distance to the true axis line) and the hinge
// axis direction (up to sign).
#pragma once

#include <algorithm>
#include <string>
#include <vector>

#include "core/expected.h"
#include "discover/discover.h"

namespace mocap::test {

struct DiscoverTruth {
  int true_bodies = 0;
  int bodies_complete = 0;              // true bodies found with all but at most one marker
  int wrong_markers = 0;                // discovered markers on another body's marker (or on none)
  int unmatched_markers = 0;            // discovered markers matching no true marker
  std::vector<int> body_map;            // discovered body -> true body index (-1: none)
  std::vector<std::string> body_lines;  // per discovered body: its markers' true labels
  bool topology_ok = false;             // same joints (parent, child, type) as the true model
  int true_joints = 0;
  int joints_right = 0;                  // true joints found with their parent, child and type
  int joints_wrong = 0;                  // discovered joints that are no true joint (or wrong type)
  std::vector<std::string> joint_lines;  // per true joint: found as what, its errors
  double worst_ball_center_mm = 0.0;     // median over frames, worst joint
  double worst_hinge_axis_deg = 0.0;
  double worst_hinge_line_mm = 0.0;  // distance of the hinge point from the true axis line
  double worst_centre_mm() const {   // the joint centre: ball centre or hinge line
    return std::max(worst_ball_center_mm, worst_hinge_line_mm);
  }
  std::string describe() const;
};

// `rec`: the simulated recording (targets.yaml, gt/poses.csv, gt/model_true.yaml).
Expected<DiscoverTruth> compare_with_truth(const std::string& rec,
                                           const discover::DiscoverResult& result);

}  // namespace mocap::test
