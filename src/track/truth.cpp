#include "track/truth.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <map>
#include <set>
#include <sstream>

#include "core/units.h"
#include "formats/csv_outputs.h"
#include "formats/joints_yaml.h"
#include "formats/targets_yaml.h"
#include "kinematics/joint_angles.h"

namespace mocap {
namespace {

double rotation_angle_deg(const Quat& a, const Quat& b) {
  const double d = std::min(1.0, std::abs(a.normalized().dot(b.normalized())));
  return 2.0 * std::acos(d) * kDegPerRad;
}

template <class Row>
std::map<std::pair<std::int64_t, std::string>, const Row*> index_rows(const std::vector<Row>& rows,
                                                                      std::string Row::*key) {
  std::map<std::pair<std::int64_t, std::string>, const Row*> m;
  for (const Row& r : rows) m[{r.frame, r.*key}] = &r;
  return m;
}

}  // namespace

// gt/markers.csv: frame,body,marker,x,y,z, then uK,vK,visK for every camera K in rig
// order (at least cameras 0 and 1), then possibly further columns (ignored).
Expected<std::vector<GtMarker>> read_gt_markers_csv(const std::string& path) {
  std::ifstream in(path);
  if (!in) return make_error(path, "", "cannot open");
  std::string line;
  if (!std::getline(in, line)) return make_error(path, "line 1", "empty file");
  if (line.rfind("frame,body,marker,x,y,z,u0,v0,vis0,u1,v1,vis1", 0) != 0) {
    return make_error(path, "line 1",
                      "expected header frame,body,marker,x,y,z,u0,v0,vis0,u1,v1,vis1");
  }
  std::vector<std::string> names;
  {
    std::stringstream hs(line);
    for (std::string h; std::getline(hs, h, ',');) names.push_back(h);
  }
  int cameras = 0;
  while (cameras < kMaxCameras) {
    const std::size_t col = 6 + 3 * static_cast<std::size_t>(cameras);
    const std::string k = std::to_string(cameras);
    if (col + 2 >= names.size() || names[col] != "u" + k || names[col + 1] != "v" + k ||
        names[col + 2] != "vis" + k)
      break;
    ++cameras;
  }
  const std::size_t fields = 6 + 3 * static_cast<std::size_t>(cameras);
  std::vector<GtMarker> out;
  int line_no = 1;
  std::vector<std::string> f(fields);
  while (std::getline(in, line)) {
    ++line_no;
    if (line.empty()) continue;
    std::stringstream ss(line);
    for (auto& s : f) {
      s.clear();
      std::getline(ss, s, ',');
    }
    GtMarker m;
    m.cameras = cameras;
    try {
      m.frame = std::stoll(f[0]);
      m.body = f[1];
      m.marker = std::stoi(f[2]);
      m.X_world = Vec3(std::stod(f[3]), std::stod(f[4]), std::stod(f[5]));
      for (std::size_t c = 0; c < static_cast<std::size_t>(cameras); ++c) {
        m.px[c] = Vec2(std::stod(f[6 + 3 * c]), std::stod(f[7 + 3 * c]));
        m.visible[c] = std::stoi(f[8 + 3 * c]) != 0;
      }
    } catch (const std::exception&) {
      return make_error(path, "line " + std::to_string(line_no), "malformed row");
    }
    out.push_back(std::move(m));
  }
  std::stable_sort(out.begin(), out.end(),
                   [](const GtMarker& a, const GtMarker& b) { return a.frame < b.frame; });
  return out;
}

Expected<GroundTruth> load_ground_truth(const std::string& gt_dir) {
  GroundTruth gt;
  auto poses = read_poses_csv(gt_dir + "/poses.csv");
  if (!poses) return poses.error();
  gt.poses = std::move(poses).value();
  std::ifstream probe(gt_dir + "/angles.csv");
  if (probe) {
    auto angles = read_angles_csv(gt_dir + "/angles.csv");
    if (!angles) return angles.error();
    gt.angles = std::move(angles).value();
  }
  auto markers = read_gt_markers_csv(gt_dir + "/markers.csv");
  if (!markers) return markers.error();
  gt.markers = std::move(markers).value();
  // The simulator's gt/angles.csv counts hinge angles from its reference configuration;
  // the tracker counts them from the model's hinge frame C (docs/kinematics.md). With
  // the true model at hand, the true angles in the tracker's convention are the angle
  // solver applied to the true poses: those are what the outputs are compared with.
  if (std::ifstream(gt_dir + "/model_true.yaml") && std::ifstream(gt_dir + "/../targets.yaml")) {
    auto targets = load_targets(gt_dir + "/../targets.yaml");
    if (!targets) return targets.error();
    auto model = load_model(gt_dir + "/model_true.yaml", *targets);
    if (!model) return model.error();
    for (const JointSpec& j : model->joints)
      gt.joints.push_back({j.name, j.parent, j.child, j.type == JointType::kHinge});
    auto angles = true_angles_from_poses(*targets, *model, gt.poses);
    if (!angles) return angles.error();
    gt.angles = std::move(angles).value();
  }
  return gt;
}

Expected<std::vector<AngleRow>> true_angles_from_poses(const TargetSet& targets,
                                                       const JointModel& model,
                                                       const std::vector<PoseRow>& poses) {
  auto solver = kinematics::JointAngleSolver::create(model, targets.bodies.size());
  if (!solver) return solver.error();
  kinematics::JointAngles out = solver->make_output();
  std::vector<kinematics::BodyPoseView> views(targets.bodies.size());
  std::vector<AngleRow> rows;
  std::size_t i = 0;
  while (i < poses.size()) {
    const std::int64_t frame = poses[i].frame;
    const std::int64_t ts = poses[i].timestamp_ns;
    for (auto& v : views) v.found = false;
    for (; i < poses.size() && poses[i].frame == frame; ++i) {
      const int b = targets.index_of(poses[i].body);
      if (b < 0) continue;
      views[static_cast<std::size_t>(b)].found = true;
      views[static_cast<std::size_t>(b)].T_world_body =
          make_iso(poses[i].q_world_body.toRotationMatrix(), poses[i].t_world_body);
    }
    solver->compute(views.data(), out);
    for (std::size_t j = 0; j < out.joints.size(); ++j) {
      const kinematics::JointAngle& a = out.joints[j];
      if (!a.valid) continue;
      AngleRow r;
      r.frame = frame;
      r.timestamp_ns = ts;
      r.joint = model.joints[j].name;
      r.type = a.type;
      r.angles_deg = Vec3(a.a0, a.a1, a.a2) * kDegPerRad;
      r.q_parent_child = a.q_parent_child;
      r.solved_by = "truth";
      rows.push_back(std::move(r));
    }
  }
  return rows;
}

AccuracyReport evaluate_against_truth(const GroundTruth& truth, const std::vector<PointRow>& points,
                                      const std::vector<PoseRow>& poses,
                                      const std::vector<AngleRow>& angles) {
  AccuracyReport rep;
  // Points: per frame, nearest point to each marker visible in two or more cameras.
  std::map<std::int64_t, std::vector<const PointRow*>> points_by_frame;
  for (const PointRow& p : points) points_by_frame[p.frame].push_back(&p);
  std::map<std::int64_t, std::vector<const GtMarker*>> markers_by_frame;
  for (const GtMarker& m : truth.markers) markers_by_frame[m.frame].push_back(&m);
  double sq_sum = 0.0;
  for (const auto& [frame, markers] : markers_by_frame) {
    const auto it = points_by_frame.find(frame);
    for (const GtMarker* m : markers) {
      if (m->views() < 2) continue;
      ++rep.marker_views;
      if (it == points_by_frame.end()) continue;
      double best = 1e300;
      for (const PointRow* p : it->second) best = std::min(best, (p->X_world - m->X_world).norm());
      if (best <= 2.0) {
        ++rep.markers_recalled;
        sq_sum += best * best;
      }
    }
  }
  rep.point_rmse_mm =
      rep.markers_recalled ? std::sqrt(sq_sum / static_cast<double>(rep.markers_recalled)) : 0.0;
  rep.points = static_cast<std::int64_t>(points.size());
  for (const auto& [frame, pts] : points_by_frame) {
    const auto mit = markers_by_frame.find(frame);
    for (const PointRow* p : pts) {
      double best = 1e300;
      if (mit != markers_by_frame.end()) {
        for (const GtMarker* m : mit->second)
          best = std::min(best, (p->X_world - m->X_world).norm());
      }
      if (best > 5.0) ++rep.points_far;
    }
  }

  // Bodies.
  std::map<std::string, std::size_t> body_slot;
  for (const PoseRow& p : truth.poses) {
    if (!body_slot.count(p.body)) {
      body_slot[p.body] = rep.bodies.size();
      rep.bodies.push_back(BodyAccuracy{p.body});
    }
  }
  std::map<std::pair<std::int64_t, std::string>, int> visible_count;
  for (const GtMarker& m : truth.markers) {
    if (m.views() >= 2) ++visible_count[{m.frame, m.body}];
  }
  std::set<std::int64_t> frames;
  for (const PoseRow& p : truth.poses) frames.insert(p.frame);
  rep.frames = static_cast<std::int64_t>(frames.size());
  const auto est = index_rows(poses, &PoseRow::body);
  std::vector<double> pos_sq(rep.bodies.size(), 0.0), rot_sq(rep.bodies.size(), 0.0);
  std::vector<std::int64_t> n_ok(rep.bodies.size(), 0);
  for (const PoseRow& t : truth.poses) {
    BodyAccuracy& b = rep.bodies[body_slot[t.body]];
    const std::size_t slot = body_slot[t.body];
    const bool visible = visible_count[{t.frame, t.body}] >= 3;
    const auto it = est.find({t.frame, t.body});
    if (visible) ++b.frames_visible;
    if (it == est.end()) continue;
    ++b.frames_found_total;
    if (visible) ++b.frames_found;
    const double dp = (it->second->t_world_body - t.t_world_body).norm();
    const double dr = rotation_angle_deg(it->second->q_world_body, t.q_world_body);
    if (dp > 10.0 || dr > 5.0) {
      ++b.wrong;
      continue;
    }
    pos_sq[slot] += dp * dp;
    rot_sq[slot] += dr * dr;
    ++n_ok[slot];
  }
  for (std::size_t i = 0; i < rep.bodies.size(); ++i) {
    if (n_ok[i] == 0) continue;
    rep.bodies[i].position_rms_mm = std::sqrt(pos_sq[i] / static_cast<double>(n_ok[i]));
    rep.bodies[i].rotation_rms_deg = std::sqrt(rot_sq[i] / static_cast<double>(n_ok[i]));
  }

  // Joints.
  std::map<std::string, std::size_t> joint_slot;
  std::vector<double> ang_sq;
  const auto est_angles = index_rows(angles, &AngleRow::joint);
  for (const AngleRow& t : truth.angles) {
    if (!joint_slot.count(t.joint)) {
      joint_slot[t.joint] = rep.joints.size();
      rep.joints.push_back(JointAccuracy{t.joint});
      ang_sq.push_back(0.0);
    }
    const std::size_t slot = joint_slot[t.joint];
    const auto it = est_angles.find({t.frame, t.joint});
    if (it == est_angles.end()) continue;
    double err = 0.0;
    if (t.type == JointType::kHinge) {
      err = std::remainder(it->second->angles_deg[0] - t.angles_deg[0], 360.0);
    } else {
      err = rotation_angle_deg(it->second->q_parent_child, t.q_parent_child);
    }
    JointAccuracy& j = rep.joints[slot];
    ++j.frames;
    if (std::abs(err) > 2.0) ++j.over_2deg;
    ang_sq[slot] += err * err;
    j.max_deg = std::max(j.max_deg, std::abs(err));
  }
  // Observability (truth.h), per frame, from the roots down: a body is observed with
  // >= 3 clean markers or through an observable joint into it.
  std::map<std::string, const GtJoint*> joint_into;
  for (const GtJoint& gj : truth.joints) joint_into.emplace(gj.child, &gj);
  const auto clean = [&](std::int64_t f, const std::string& body) {
    const auto it = visible_count.find({f, body});
    return it == visible_count.end() ? 0 : it->second;
  };
  for (const std::int64_t f : frames) {
    std::map<std::string, bool> observed;
    const auto body_observed = [&](const std::string& body, const auto& self) -> bool {
      if (const auto it = observed.find(body); it != observed.end()) return it->second;
      observed[body] = false;  // a loop in the model never observes a body through itself
      bool o = clean(f, body) >= 3;
      if (!o) {
        const auto it = joint_into.find(body);
        o = it != joint_into.end() && clean(f, body) >= (it->second->hinge ? 1 : 2) &&
            self(it->second->parent, self);
      }
      observed[body] = o;
      return o;
    };
    for (const GtJoint& gj : truth.joints) {
      const auto js = joint_slot.find(gj.name);
      if (js == joint_slot.end()) continue;
      if (!body_observed(gj.parent, body_observed) || clean(f, gj.child) < (gj.hinge ? 1 : 2))
        continue;
      ++rep.joints[js->second].observable;
      if (est_angles.count({f, gj.name})) ++rep.joints[js->second].valid_observable;
    }
  }
  for (std::size_t i = 0; i < rep.joints.size(); ++i) {
    if (rep.joints[i].frames > 0) {
      rep.joints[i].rms_deg = std::sqrt(ang_sq[i] / static_cast<double>(rep.joints[i].frames));
    }
  }
  return rep;
}

std::string format_accuracy(const AccuracyReport& r) {
  std::ostringstream s;
  char buf[256];
  std::snprintf(
      buf, sizeof buf,
      "accuracy against ground truth (%lld frames)\n"
      "  3D points: recall %.2f%% (%lld of %lld markers seen by 2+ cameras), "
      "RMSE %.4f mm, %lld of %lld points far (> 5 mm) from any marker\n",
      static_cast<long long>(r.frames),
      r.marker_views
          ? 100.0 * static_cast<double>(r.markers_recalled) / static_cast<double>(r.marker_views)
          : 0.0,
      static_cast<long long>(r.markers_recalled), static_cast<long long>(r.marker_views),
      r.point_rmse_mm, static_cast<long long>(r.points_far), static_cast<long long>(r.points));
  s << buf;
  for (const BodyAccuracy& b : r.bodies) {
    std::snprintf(buf, sizeof buf,
                  "  body %-10s found %.2f%% of %lld frames with >= 3 markers visible, wrong %lld, "
                  "position RMS %.4f mm, rotation RMS %.4f deg\n",
                  b.body.c_str(),
                  b.frames_visible ? 100.0 * static_cast<double>(b.frames_found) /
                                         static_cast<double>(b.frames_visible)
                                   : 0.0,
                  static_cast<long long>(b.frames_visible), static_cast<long long>(b.wrong),
                  b.position_rms_mm, b.rotation_rms_deg);
    s << buf;
  }
  for (const JointAccuracy& j : r.joints) {
    std::snprintf(buf, sizeof buf,
                  "  joint %-10s angle error RMS %.4f deg, max %.4f deg over %lld frames, "
                  "%lld > 2 deg",
                  j.joint.c_str(), j.rms_deg, j.max_deg, static_cast<long long>(j.frames),
                  static_cast<long long>(j.over_2deg));
    s << buf;
    if (j.observable > 0) {
      std::snprintf(
          buf, sizeof buf, "; valid in %.2f%% of %lld observable frames",
          100.0 * static_cast<double>(j.valid_observable) / static_cast<double>(j.observable),
          static_cast<long long>(j.observable));
      s << buf;
    }
    s << '\n';
  }
  return s.str();
}

}  // namespace mocap
