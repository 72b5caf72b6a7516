// Design: see evaluation.h. Straightforward statistics over rows indexed by (frame, name);
// rotation means are the principal eigenvector of sum(q q^T) (sign-free quaternion mean).
#include "track/evaluation.h"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <fstream>
#include <limits>
#include <map>
#include <sstream>

#include "core/rotation.h"
#include "core/units.h"

namespace mocap {
namespace {

double angle_between_lines_deg(const Vec3& a, const Vec3& b) {
  const double c = std::abs(a.normalized().dot(b.normalized()));
  const double s = a.normalized().cross(b.normalized()).norm();
  return std::atan2(s, c) * kDegPerRad;
}

// Distance of `p` from the line through `c` with direction `d`.
double point_line_distance(const Vec3& p, const Vec3& c, const Vec3& d) {
  return (p - c).cross(d.normalized()).norm();
}

double geodesic_deg(const Quat& a, const Quat& b) {
  const double d = std::min(1.0, std::abs(a.normalized().dot(b.normalized())));
  return 2.0 * std::acos(d) * kDegPerRad;
}

Quat mean_rotation(const std::vector<Quat>& qs) {
  Eigen::Matrix4d M = Eigen::Matrix4d::Zero();
  for (const Quat& q : qs) {
    const Eigen::Vector4d v = q.normalized().coeffs();
    M += v * v.transpose();
  }
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix4d> es(M);
  const Eigen::Vector4d v = es.eigenvectors().col(3);  // largest eigenvalue
  return Quat(v(3), v(0), v(1), v(2)).normalized();
}

std::vector<std::string> split_csv(const std::string& line) {
  std::vector<std::string> f;
  std::stringstream ss(line);
  std::string s;
  while (std::getline(ss, s, ',')) f.push_back(s);
  return f;
}

}  // namespace

Expected<std::vector<CalibrationError>> calibration_errors(const JointModel& estimate,
                                                           const JointModel& truth) {
  std::vector<CalibrationError> out;
  for (const JointSpec& t : truth.joints) {
    const int i = estimate.index_of(t.name);
    if (i < 0) return make_error("estimate", t.name, "joint missing");
    const JointSpec& e = estimate.joints[static_cast<std::size_t>(i)];
    if (e.type != t.type)
      return make_error("estimate", t.name, "joint type differs from the truth");
    if (!e.calibrated || !t.calibrated)
      return make_error("estimate", t.name, "joint not calibrated");
    CalibrationError r;
    r.joint = t.name;
    r.type = t.type;
    r.center_parent_mm = (e.center_parent - t.center_parent).norm();
    r.center_child_mm = (e.center_child - t.center_child).norm();
    if (t.type == JointType::kHinge) {
      r.axis_parent_deg = angle_between_lines_deg(e.axis_parent, t.axis_parent);
      r.axis_child_deg = angle_between_lines_deg(e.axis_child, t.axis_child);
      r.axis_position_parent_mm =
          point_line_distance(t.center_parent, e.center_parent, e.axis_parent);
      r.axis_position_child_mm = point_line_distance(t.center_child, e.center_child, e.axis_child);
    }
    out.push_back(r);
  }
  return out;
}

Expected<std::vector<Segment>> read_segments_csv(const std::string& path) {
  std::ifstream in(path);
  if (!in) return make_error(path, "", "cannot open");
  std::string line;
  if (!std::getline(in, line) ||
      line.rfind("segment,kind,first_frame,last_frame,tx,ty,tz", 0) != 0) {
    return make_error(path, "line 1",
                      "expected header segment,kind,first_frame,last_frame,tx,ty,tz");
  }
  std::vector<Segment> out;
  int line_no = 1;
  while (std::getline(in, line)) {
    ++line_no;
    if (line.empty()) continue;
    const std::vector<std::string> f = split_csv(line);
    const std::string where = "line " + std::to_string(line_no);
    if (f.size() < 7) return make_error(path, where, "expected 7 fields");
    if (f[1] != "hold" && f[1] != "move")
      return make_error(path, where, "kind must be hold or move");
    Segment s;
    try {
      s.index = std::stoi(f[0]);
      s.hold = f[1] == "hold";
      s.first_frame = std::stoll(f[2]);
      s.last_frame = std::stoll(f[3]);
      s.t_robot_mm = Vec3(std::stod(f[4]), std::stod(f[5]), std::stod(f[6]));
    } catch (const std::exception&) {
      return make_error(path, where, "not a number");
    }
    if (s.last_frame < s.first_frame) return make_error(path, where, "last_frame < first_frame");
    out.push_back(s);
  }
  return out;
}

std::vector<BodyDistanceError> distance_errors(const std::vector<PoseRow>& poses,
                                               const std::vector<Segment>& segments) {
  std::vector<std::string> bodies;
  for (const PoseRow& p : poses) {
    if (std::find(bodies.begin(), bodies.end(), p.body) == bodies.end()) bodies.push_back(p.body);
  }
  // Mean position of every body in every hold segment.
  const std::size_t S = segments.size();
  std::map<std::string, std::vector<Vec3>> sum;
  std::map<std::string, std::vector<int>> count;
  for (const std::string& b : bodies) {
    sum[b].assign(S, Vec3::Zero());
    count[b].assign(S, 0);
  }
  for (const PoseRow& p : poses) {
    for (std::size_t s = 0; s < S; ++s) {
      if (segments[s].hold && p.frame >= segments[s].first_frame &&
          p.frame <= segments[s].last_frame) {
        sum[p.body][s] += p.t_world_body;
        ++count[p.body][s];
      }
    }
  }
  std::vector<BodyDistanceError> out;
  for (const std::string& b : bodies) {
    BodyDistanceError e;
    e.body = b;
    double sq = 0.0, signed_sum = 0.0;
    for (std::size_t s = 0; s + 2 < S; ++s) {
      if (!segments[s].hold || segments[s + 1].hold || !segments[s + 2].hold) continue;
      DistancePair pr;
      pr.hold_a = segments[s].index;
      pr.hold_b = segments[s + 2].index;
      pr.true_mm = (segments[s + 2].t_robot_mm - segments[s].t_robot_mm).norm();
      pr.measured_mm = std::numeric_limits<double>::quiet_NaN();
      const int na = count[b][s], nb = count[b][s + 2];
      if (na > 0 && nb > 0) {
        const Vec3 a = sum[b][s] / static_cast<double>(na),
                   c = sum[b][s + 2] / static_cast<double>(nb);
        pr.measured_mm = (c - a).norm();
        const double err = pr.measured_mm - pr.true_mm;
        sq += err * err;
        signed_sum += err;
        e.max_abs_error_mm = std::max(e.max_abs_error_mm, std::abs(err));
        ++e.pairs_used;
      }
      e.pairs.push_back(pr);
    }
    if (e.pairs_used > 0) {
      e.rmse_mm = std::sqrt(sq / e.pairs_used);
      e.mean_error_mm = signed_sum / e.pairs_used;
    }
    out.push_back(e);
  }
  return out;
}

std::vector<JointPrecision> joint_precision(const JointModel& model,
                                            const std::vector<PoseRow>& poses,
                                            const std::vector<AngleRow>& angles) {
  std::map<std::pair<std::int64_t, std::string>, const PoseRow*> by_frame;
  for (const PoseRow& p : poses) by_frame[{p.frame, p.body}] = &p;
  std::vector<JointPrecision> out;
  for (const JointSpec& j : model.joints) {
    JointPrecision r;
    r.joint = j.name;
    r.type = j.type;
    std::vector<Vec3> t_rel;
    std::vector<Quat> q_rel;
    for (const auto& [key, parent] : by_frame) {
      if (key.second != j.parent) continue;
      auto it = by_frame.find({key.first, j.child});
      if (it == by_frame.end()) continue;
      const PoseRow* child = it->second;
      const Quat qp = parent->q_world_body.normalized();
      q_rel.push_back(qp.conjugate() * child->q_world_body.normalized());
      t_rel.push_back(qp.conjugate() * (child->t_world_body - parent->t_world_body));
    }
    r.frames = static_cast<std::int64_t>(t_rel.size());
    if (!t_rel.empty()) {
      Vec3 mean = Vec3::Zero();
      for (const Vec3& t : t_rel) mean += t;
      mean /= static_cast<double>(t_rel.size());
      double sq = 0.0;
      for (const Vec3& t : t_rel) sq += (t - mean).squaredNorm();
      r.translation_std_mm = std::sqrt(sq / static_cast<double>(t_rel.size()));
      const Quat qm = mean_rotation(q_rel);
      double sr = 0.0;
      for (const Quat& q : q_rel) sr += std::pow(geodesic_deg(qm, q), 2);
      r.rotation_std_deg = std::sqrt(sr / static_cast<double>(q_rel.size()));
    }
    // Joint angles: per component variance, averaged over the components used.
    std::vector<Vec3> a;
    for (const AngleRow& row : angles) {
      if (row.joint == j.name) a.push_back(row.angles_deg);
    }
    if (!a.empty()) {
      Vec3 mean = Vec3::Zero();
      for (const Vec3& v : a) mean += v;
      mean /= static_cast<double>(a.size());
      Vec3 var = Vec3::Zero();
      for (const Vec3& v : a) var += (v - mean).cwiseAbs2();
      var /= static_cast<double>(a.size());
      r.angle_std_deg = j.type == JointType::kHinge ? std::sqrt(var(0)) : std::sqrt(var.mean());
    }
    out.push_back(r);
  }
  return out;
}

std::vector<JointAngleError> angle_errors(const std::vector<AngleRow>& truth,
                                          const std::vector<AngleRow>& measured,
                                          std::vector<AngleErrorSample>* series) {
  std::map<std::pair<std::int64_t, std::string>, const AngleRow*> meas;
  for (const AngleRow& m : measured) meas[{m.frame, m.joint}] = &m;
  std::vector<JointAngleError> out;
  std::map<std::string, std::size_t> index;
  std::vector<std::vector<double>> errors;
  for (const AngleRow& t : truth) {
    auto [it, inserted] = index.try_emplace(t.joint, out.size());
    if (inserted) {
      JointAngleError e;
      e.joint = t.joint;
      e.type = t.type;
      out.push_back(e);
      errors.emplace_back();
    }
    auto m = meas.find({t.frame, t.joint});
    if (m == meas.end()) continue;
    const double err = t.type == JointType::kHinge
                           ? m->second->angles_deg(0) - t.angles_deg(0)
                           : geodesic_deg(t.q_parent_child, m->second->q_parent_child);
    errors[it->second].push_back(err);
    if (series) series->push_back({t.frame, t.timestamp_ns, t.joint, err});
  }
  for (std::size_t k = 0; k < out.size(); ++k) {
    const std::vector<double>& v = errors[k];
    JointAngleError& e = out[k];
    e.frames = static_cast<std::int64_t>(v.size());
    if (v.empty()) continue;
    double sq = 0.0, sum = 0.0, sq_fine = 0.0;
    for (double x : v) {
      sq += x * x;
      sum += x;
      e.max_deg = std::max(e.max_deg, std::abs(x));
      if (std::abs(x) > kGrossAngleErrorDeg) {
        ++e.gross;
      } else {
        sq_fine += x * x;
      }
    }
    if (e.gross < e.frames)
      e.rms_without_gross_deg = std::sqrt(sq_fine / static_cast<double>(e.frames - e.gross));
    const double n = static_cast<double>(v.size());
    e.rms_deg = std::sqrt(sq / n);
    e.mean_deg = sum / n;
    e.rms_debiased_deg = e.type == JointType::kHinge
                             ? std::sqrt(std::max(0.0, sq / n - e.mean_deg * e.mean_deg))
                             : e.rms_deg;
  }
  return out;
}

}  // namespace mocap
