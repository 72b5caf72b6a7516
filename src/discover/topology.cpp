#include "discover/topology.h"

#include <algorithm>
#include <numeric>
#include <queue>

namespace mocap::discover {
namespace {

constexpr int kMaxPoses = 400;

// Returns false when the pair is no joint candidate; fills `edge` (parent = a) otherwise.
bool score_pair(const DiscoveredBody& A, const DiscoveredBody& B, int a, int b,
                const DiscoverOptions& opt, JointEdge& edge, bool& low_motion) {
  low_motion = false;
  std::vector<std::size_t> frames;
  for (std::size_t f = 0; f < A.found.size(); ++f)
    if (A.found[f] && B.found[f]) frames.push_back(f);
  if (static_cast<int>(frames.size()) < opt.linear.min_poses) return false;
  std::vector<kinematics::RelativePose> poses;
  const std::size_t n = std::min<std::size_t>(frames.size(), kMaxPoses);
  for (std::size_t i = 0; i < n; ++i) {
    const std::size_t f = frames[i * frames.size() / n];
    poses.push_back(kinematics::relative_pose(A.T_world_body[f], B.T_world_body[f]));
  }
  kinematics::LinearOptions relaxed = opt.linear;
  relaxed.min_motion_deg = 0.0;
  relaxed.max_hinge_off_axis_ratio = 1e9;
  auto hinge = kinematics::estimate_hinge(poses, relaxed, "pair");
  auto ball = kinematics::estimate_ball(poses, relaxed, "pair");
  if (!ball) return false;
  const kinematics::LinearDiagnostics& d = ball->diagnostics;
  const double s5 = d.singular_value_deg(4), s6 = d.singular_value_deg(5);
  if (s5 < opt.linear.min_motion_deg) {
    low_motion = true;
    return false;
  }
  edge.parent = a;
  edge.child = b;
  // Hinge when the rank-5 test says so AND the hinge explains the motion as well as a
  // ball (a ball joint turned little about its third axis passes the ratio test alone).
  if (hinge && s6 / s5 <= opt.linear.max_hinge_off_axis_ratio &&
      hinge->diagnostics.residual_rms_mm <= 2.0 * d.residual_rms_mm + 0.1) {
    edge.type = JointType::kHinge;
    edge.diagnostics = hinge->diagnostics;
    edge.center_parent = hinge->center_parent;
    edge.axis_parent = hinge->axis_parent;
  } else if (s6 >= opt.linear.min_motion_deg) {
    edge.type = JointType::kBall;
    edge.diagnostics = d;
    edge.center_parent = ball->center_parent;
  } else {
    low_motion = true;  // neither a clean hinge nor enough motion for a ball
    return false;
  }
  edge.residual_mm = edge.diagnostics.residual_rms_mm;
  return edge.residual_mm <= opt.max_joint_residual_mm;
}

}  // namespace

bool joint_candidate(const DiscoveredBody& P, const DiscoveredBody& C, const DiscoverOptions& opt,
                     JointEdge& edge) {
  bool low = false;
  return score_pair(P, C, 0, 1, opt, edge, low);
}

TopologyResult infer_topology(const std::vector<DiscoveredBody>& bodies,
                              const DiscoverOptions& opt) {
  TopologyResult out;
  const int nb = static_cast<int>(bodies.size());
  std::vector<JointEdge> candidates;
  for (int a = 0; a < nb; ++a) {
    for (int b = a + 1; b < nb; ++b) {
      JointEdge e;
      bool low = false;
      if (score_pair(bodies[static_cast<std::size_t>(a)], bodies[static_cast<std::size_t>(b)], a, b,
                     opt, e, low))
        candidates.push_back(e);
      else if (low)
        out.low_motion_pairs.emplace_back(a, b);
    }
  }
  std::stable_sort(
      candidates.begin(), candidates.end(),
      [](const JointEdge& x, const JointEdge& y) { return x.residual_mm < y.residual_mm; });
  std::vector<int> comp(static_cast<std::size_t>(nb));
  std::iota(comp.begin(), comp.end(), 0);
  auto find = [&](int x) {
    while (comp[static_cast<std::size_t>(x)] != x)
      x = comp[static_cast<std::size_t>(x)] =
          comp[static_cast<std::size_t>(comp[static_cast<std::size_t>(x)])];
    return x;
  };
  std::vector<std::vector<std::pair<int, const JointEdge*>>> adj(static_cast<std::size_t>(nb));
  for (const JointEdge& e : candidates) {
    const int x = find(e.parent), y = find(e.child);
    if (x == y) continue;
    comp[static_cast<std::size_t>(x)] = y;
    adj[static_cast<std::size_t>(e.parent)].emplace_back(e.child, &e);
    adj[static_cast<std::size_t>(e.child)].emplace_back(e.parent, &e);
  }
  // Trees: members, root (least world motion), breadth-first order.
  std::vector<std::vector<int>> trees;
  std::vector<int> tree_of(static_cast<std::size_t>(nb), -1);
  for (int b = 0; b < nb; ++b) {
    const int r = find(b);
    if (tree_of[static_cast<std::size_t>(r)] < 0) {
      tree_of[static_cast<std::size_t>(r)] = static_cast<int>(trees.size());
      trees.emplace_back();
    }
    trees[static_cast<std::size_t>(tree_of[static_cast<std::size_t>(r)])].push_back(b);
  }
  std::stable_sort(trees.begin(), trees.end(),
                   [](const auto& x, const auto& y) { return x.size() > y.size(); });
  for (const auto& tree : trees) {
    int root = tree.front();
    for (int b : tree)
      if (bodies[static_cast<std::size_t>(b)].motion_rms_mm <
          bodies[static_cast<std::size_t>(root)].motion_rms_mm)
        root = b;
    std::vector<char> seen(static_cast<std::size_t>(nb), 0);
    std::queue<int> q;
    q.push(root);
    seen[static_cast<std::size_t>(root)] = 1;
    while (!q.empty()) {
      const int p = q.front();
      q.pop();
      out.body_order.push_back(p);
      auto next = adj[static_cast<std::size_t>(p)];
      std::sort(next.begin(), next.end());
      for (const auto& [c, e] : next) {
        if (seen[static_cast<std::size_t>(c)]) continue;
        seen[static_cast<std::size_t>(c)] = 1;
        JointEdge j = *e;
        if (j.parent != p) {  // re-estimate with the parent on the root's side
          bool low = false;
          score_pair(bodies[static_cast<std::size_t>(p)], bodies[static_cast<std::size_t>(c)], p, c,
                     opt, j, low);
          j.parent = p;
          j.child = c;
        }
        out.joints.push_back(j);
        q.push(c);
      }
    }
  }
  return out;
}

}  // namespace mocap::discover
