#include "discover_truth.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <map>

#include "core/median.h"
#include "formats/csv_outputs.h"

namespace mocap::test {
namespace {

double median(std::vector<double> v) { return v.empty() ? 1e9 : median_in_place(v); }

}  // namespace

std::string DiscoverTruth::describe() const {
  char buf[400];
  std::snprintf(buf, sizeof buf,
                "true bodies %d, complete %d, wrong markers %d, unmatched markers %d, joints "
                "right %d / %d (%d wrong), topology %s, ball centre %.3f mm, hinge axis %.3f deg, "
                "hinge line %.3f mm",
                true_bodies, bodies_complete, wrong_markers, unmatched_markers, joints_right,
                true_joints, joints_wrong, topology_ok ? "ok" : "WRONG", worst_ball_center_mm,
                worst_hinge_axis_deg, worst_hinge_line_mm);
  return buf;
}

Expected<DiscoverTruth> compare_with_truth(const std::string& rec,
                                           const discover::DiscoverResult& r) {
  auto targets = load_targets(rec + "/targets.yaml");
  if (!targets) return targets.error();
  auto model = load_model(rec + "/gt/model_true.yaml", *targets);
  if (!model) return model.error();
  auto poses = read_poses_csv(rec + "/gt/poses.csv");
  if (!poses) return poses.error();
  const std::size_t nt = targets->bodies.size(), nd = r.targets.bodies.size();
  const std::size_t frames = r.input.frames.size();
  // True poses per frame index (gt rows are per frame, frames from 0 as in frames.csv).
  std::vector<std::vector<Iso3>> T_true(frames, std::vector<Iso3>(nt, Iso3::Identity()));
  for (const PoseRow& p : *poses) {
    const int b = targets->index_of(p.body);
    if (b < 0 || p.frame < 0 || static_cast<std::size_t>(p.frame) >= frames) continue;
    Iso3 T = Iso3::Identity();
    T.linear() = p.q_world_body.normalized().toRotationMatrix();
    T.translation() = p.t_world_body;
    T_true[static_cast<std::size_t>(p.frame)][static_cast<std::size_t>(b)] = T;
  }
  DiscoverTruth out;
  out.true_bodies = static_cast<int>(nt);
  out.body_map.assign(nd, -1);
  std::vector<std::vector<char>> covered(nt);
  for (std::size_t b = 0; b < nt; ++b) covered[b].assign(targets->bodies[b].markers_body.size(), 0);
  for (std::size_t d = 0; d < nd; ++d) {
    const auto& markers = r.targets.bodies[d].markers_body;
    std::vector<std::pair<int, int>> label(markers.size(), {-1, -1});
    for (std::size_t m = 0; m < markers.size(); ++m) {
      std::map<std::pair<int, int>, int> votes;
      for (std::size_t f = 0; f < frames; f += 3) {
        const auto& obs = r.input.frames[f].bodies[d];
        if (!obs.found) continue;
        const Vec3 X = obs.T_world_body * markers[m];
        for (std::size_t b = 0; b < nt; ++b)
          for (std::size_t k = 0; k < targets->bodies[b].markers_body.size(); ++k)
            if ((T_true[f][b] * targets->bodies[b].markers_body[k] - X).norm() < 3.0)
              ++votes[{static_cast<int>(b), static_cast<int>(k)}];
      }
      int best = 0;
      for (const auto& [key, n] : votes)
        if (n > best) {
          best = n;
          label[m] = key;
        }
    }
    std::map<int, int> body_votes;
    for (const auto& l : label)
      if (l.first >= 0) ++body_votes[l.first];
    int best = 0;
    for (const auto& [b, n] : body_votes)
      if (n > best) {
        best = n;
        out.body_map[d] = b;
      }
    std::string line = r.targets.bodies[d].name + " ->";
    for (const auto& l : label)
      line += l.first < 0 ? std::string(" ?")
                          : " " + targets->bodies[static_cast<std::size_t>(l.first)].name + ":" +
                                std::to_string(l.second);
    {  // marker position errors after aligning the found target onto the true one
      std::vector<std::size_t> idx;
      for (std::size_t m = 0; m < markers.size(); ++m)
        if (label[m].first >= 0 && label[m].first == out.body_map[d]) idx.push_back(m);
      if (idx.size() >= 3) {
        Eigen::Matrix3Xd S(3, static_cast<Eigen::Index>(idx.size())), D = S;
        for (std::size_t i = 0; i < idx.size(); ++i) {
          S.col(static_cast<Eigen::Index>(i)) = markers[idx[i]];
          D.col(static_cast<Eigen::Index>(i)) =
              targets->bodies[static_cast<std::size_t>(label[idx[i]].first)]
                  .markers_body[static_cast<std::size_t>(label[idx[i]].second)];
        }
        Iso3 T;
        T.matrix() = Eigen::umeyama(S, D, false);
        line += " | errors mm:";
        for (std::size_t i = 0; i < idx.size(); ++i) {
          char b[32];
          std::snprintf(
              b, sizeof b, " %.2f",
              (T * S.col(static_cast<Eigen::Index>(i)) - D.col(static_cast<Eigen::Index>(i)))
                  .norm());
          line += b;
        }
      }
    }
    out.body_lines.push_back(line);
    for (const auto& l : label) {
      if (l.first < 0) {
        ++out.unmatched_markers;
      } else if (l.first != out.body_map[d]) {
        ++out.wrong_markers;
      } else {
        covered[static_cast<std::size_t>(l.first)][static_cast<std::size_t>(l.second)] = 1;
      }
    }
  }
  for (std::size_t b = 0; b < nt; ++b) {
    const int have = static_cast<int>(std::count(covered[b].begin(), covered[b].end(), 1));
    if (have + 1 >= static_cast<int>(covered[b].size())) ++out.bodies_complete;
  }
  // Topology and joint parameters.
  out.topology_ok = r.model.joints.size() == model->joints.size();
  out.true_joints = static_cast<int>(model->joints.size());
  std::vector<char> matched(r.model.joints.size(), 0);
  for (const JointSpec& tj : model->joints) {
    const JointSpec* dj = nullptr;
    for (std::size_t k = 0; k < r.model.joints.size(); ++k) {
      const JointSpec& j = r.model.joints[k];
      if (out.body_map[static_cast<std::size_t>(j.parent_index)] == tj.parent_index &&
          out.body_map[static_cast<std::size_t>(j.child_index)] == tj.child_index &&
          j.type == tj.type) {
        dj = &j;
        matched[k] = 1;
      }
    }
    if (dj == nullptr) {
      out.topology_ok = false;
      out.joint_lines.push_back(tj.name + ": not found");
      continue;
    }
    ++out.joints_right;
    std::vector<double> centre, axis, line;
    for (std::size_t f = 0; f < frames; ++f) {
      const auto& obs = r.input.frames[f].bodies[static_cast<std::size_t>(dj->parent_index)];
      if (!obs.found) continue;
      const Iso3& Tt = T_true[f][static_cast<std::size_t>(tj.parent_index)];
      const Vec3 c_disc = obs.T_world_body * dj->center_parent;
      const Vec3 c_true = Tt * tj.center_parent;
      if (tj.type == JointType::kBall) {
        centre.push_back((c_disc - c_true).norm());
      } else {
        const Vec3 a_disc = obs.T_world_body.linear() * dj->axis_parent;
        const Vec3 a_true = (Tt.linear() * tj.axis_parent).normalized();
        axis.push_back(std::acos(std::min(1.0, std::abs(a_disc.normalized().dot(a_true)))) *
                       57.29577951308232);
        const Vec3 v = c_disc - c_true;
        line.push_back((v - v.dot(a_true) * a_true).norm());
      }
    }
    char buf[160];
    if (tj.type == JointType::kBall) {
      out.worst_ball_center_mm = std::max(out.worst_ball_center_mm, median(centre));
      std::snprintf(buf, sizeof buf, "%s: %s, ball centre %.3f mm", tj.name.c_str(),
                    dj->name.c_str(), median(centre));
    } else {
      out.worst_hinge_axis_deg = std::max(out.worst_hinge_axis_deg, median(axis));
      out.worst_hinge_line_mm = std::max(out.worst_hinge_line_mm, median(line));
      std::snprintf(buf, sizeof buf, "%s: %s, hinge axis %.3f deg, line %.3f mm", tj.name.c_str(),
                    dj->name.c_str(), median(axis), median(line));
    }
    out.joint_lines.push_back(buf);
  }
  for (std::size_t k = 0; k < r.model.joints.size(); ++k) {
    if (matched[k]) continue;
    ++out.joints_wrong;
    const JointSpec& j = r.model.joints[k];
    auto name = [&](int d) {
      const int t = out.body_map[static_cast<std::size_t>(d)];
      return t < 0 ? std::string("?") : targets->bodies[static_cast<std::size_t>(t)].name;
    };
    out.joint_lines.push_back("wrong joint " + j.name + " (" +
                              (j.type == JointType::kBall ? "ball" : "hinge") +
                              "): " + name(j.parent_index) + " -> " + name(j.child_index));
  }
  return out;
}

}  // namespace mocap::test
