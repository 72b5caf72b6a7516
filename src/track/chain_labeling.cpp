// Design: the labelling half of chain tracking (chain_solver.h, step 2 and 3): which of
// the frame's available points are which markers of a child body, given the parent's
// pose and the calibrated joint, and the initial joint rotation from those labels. A point
// is a candidate only when its gate is less than half the closest two markers' distance
// (otherwise it could be any of them, and would tie with a whole point of one).
#include <algorithm>
#include <cmath>
#include <limits>

#include "track/chain_solver.h"

namespace mocap {

using chain_detail::kMaxCandidates;
using chain_detail::LabelSearch;

bool LabelSearch::pair_ok(int m, int p, int mm, int q) const noexcept {
  const double d_meas = (pts[p].X_world - pts[q].X_world).norm();
  const double d_model =
      ((*markers)[static_cast<std::size_t>(m)] - (*markers)[static_cast<std::size_t>(mm)]).norm();
  const double tp = tol_mm[static_cast<std::size_t>(p)];
  const double tq = tol_mm[static_cast<std::size_t>(q)];
  return std::abs(d_meas - d_model) <= std::sqrt(tp * tp + tq * tq);
}

void LabelSearch::visit(int m, int count) noexcept {
  if (++nodes > max_nodes) {
    hit_limit = true;
    return;
  }
  if (count + (k - m) < best_count) return;  // cannot reach the best count any more
  if (m == k) {
    if (count > best_count) {
      best_count = count;
      best = cur;
      agree.fill(true);
    } else if (count == best_count) {
      for (int i = 0; i < k; ++i)
        if (cur[static_cast<std::size_t>(i)] != best[static_cast<std::size_t>(i)])
          agree[static_cast<std::size_t>(i)] = false;
    }
    return;
  }
  const auto um = static_cast<std::size_t>(m);
  for (int c = 0; c < cand_count[um]; ++c) {
    const int p = cand[um][static_cast<std::size_t>(c)];
    bool ok = true;
    for (int mm = 0; mm < m && ok; ++mm) {
      const int q = cur[static_cast<std::size_t>(mm)];
      if (q < 0) continue;
      ok = q != p && pair_ok(m, p, mm, q);
    }
    if (!ok) continue;
    cur[um] = static_cast<std::int16_t>(p);
    visit(m + 1, count + 1);
    cur[um] = -1;
    if (hit_limit) return;
  }
  visit(m + 1, count);
}

int ChainSolver::label_child(int j, const Iso3& T_world_parent, const MeasuredPoint* pts, int n,
                             std::int64_t t_ns,
                             std::array<std::int16_t, kMaxMarkers>& labels) noexcept {
  const ChainJoint& cj = model_.joint(j);
  const std::vector<Vec3>& markers = model_.markers(cj.child);
  const Mat3 R_wp = T_world_parent.linear();
  const Vec3 c_w = T_world_parent * cj.c_parent;
  const Vec3 a_w = R_wp * cj.axis_parent;
  const Prior& prior = priors_[static_cast<std::size_t>(j)];
  const double age_s = static_cast<double>(t_ns - prior.t_ns) * 1e-9;
  const bool warm = prior.valid && age_s > 0.0 && age_s <= config_.max_prior_age_s;
  const Mat3 R_pred_w = R_wp * prior.R_parent_child;

  LabelSearch& s = search_;
  s.pts = pts;
  s.markers = &markers;
  s.k = static_cast<int>(markers.size());
  for (int p = 0; p < n; ++p)
    s.tol_mm[static_cast<std::size_t>(p)] = config_.gate_sigmas * std::sqrt(sigma_sq(p, pts[p]));
  // A point identifies a marker only when its gate leaves out every other marker of the
  // body: gate < half the closest two markers' distance. A partial point less certain than
  // that (a sliver of a ball) could be any of them, and would tie with a whole point.
  double min_sep = std::numeric_limits<double>::infinity();
  for (std::size_t a = 0; a < markers.size(); ++a)
    for (std::size_t b = a + 1; b < markers.size(); ++b)
      min_sep = std::min(min_sep, (markers[a] - markers[b]).norm());
  for (int m = 0; m < s.k; ++m) {
    const auto um = static_cast<std::size_t>(m);
    s.cand_count[um] = 0;
    s.cur[um] = -1;
    labels[um] = -1;
    const Vec3 v = markers[um] - cj.c_child;  // lever, child frame
    const double h = cj.axis_child.dot(v);
    const double rho = cj.type == JointType::kHinge ? (v - h * cj.axis_child).norm() : v.norm();
    const Vec3 X_pred = c_w + R_pred_w * v;
    const double travel_mm = warm ? rho * max_rate_rad_per_s_ * age_s : 0.0;
    bool overflow = false;
    for (int p = 0; p < n && !overflow; ++p) {
      if (!available_[static_cast<std::size_t>(p)]) continue;
      const double tol = s.tol_mm[static_cast<std::size_t>(p)];
      if (!(2.0 * tol < min_sep)) continue;
      const Vec3 d = pts[p].X_world - c_w;
      if (cj.type == JointType::kHinge) {
        const double dh = a_w.dot(d);
        if (std::abs(dh - h) > tol || std::abs((d - dh * a_w).norm() - rho) > tol) continue;
      } else if (std::abs(d.norm() - rho) > tol) {
        continue;
      }
      if (warm && (pts[p].X_world - X_pred).norm() > travel_mm + tol) continue;
      if (s.cand_count[um] == kMaxCandidates) {
        overflow = true;
        break;
      }
      s.cand[um][static_cast<std::size_t>(s.cand_count[um]++)] = static_cast<std::int16_t>(p);
    }
    if (overflow) {
      s.cand_count[um] = 0;  // too many points on its locus: this marker is ambiguous
      ++counters_.ambiguous_labels;
    }
  }
  s.best_count = 0;
  s.best.fill(-1);
  s.agree.fill(true);
  s.nodes = 0;
  s.max_nodes = config_.max_search_nodes;
  s.hit_limit = false;
  s.visit(0, 0);
  if (s.hit_limit) {
    ++counters_.node_limit_hits;
    return 0;
  }
  int count = 0;
  for (int m = 0; m < s.k; ++m) {
    const auto um = static_cast<std::size_t>(m);
    if (s.best[um] < 0) continue;
    if (!s.agree[um]) {
      ++counters_.ambiguous_labels;
      continue;
    }
    labels[um] = s.best[um];
    ++count;
  }
  const int needed = (cj.type == JointType::kHinge ? 1 : 2) + (warm ? 0 : 1);
  return count >= needed ? count : 0;
}

bool ChainSolver::initial_rotation(int j, const Iso3& T_world_parent, const MeasuredPoint* pts,
                                   const std::array<std::int16_t, kMaxMarkers>& labels,
                                   std::int64_t t_ns, Mat3& R) const noexcept {
  const ChainJoint& cj = model_.joint(j);
  const Prior& prior = priors_[static_cast<std::size_t>(j)];
  const double age_s = static_cast<double>(t_ns - prior.t_ns) * 1e-9;
  if (prior.valid && age_s > 0.0 && age_s <= config_.max_prior_age_s) {
    R = prior.R_parent_child;
    return true;
  }
  const std::vector<Vec3>& markers = model_.markers(cj.child);
  const Mat3 R_pw = T_world_parent.linear().transpose();
  const Vec3 c_w = T_world_parent * cj.c_parent;
  if (cj.type == JointType::kHinge) {
    for (std::size_t m = 0; m < markers.size(); ++m) {
      if (labels[m] < 0) continue;
      // Both vectors in the parent's frame, projected on the plane normal to the axis.
      const Vec3 a = cj.axis_parent;
      Vec3 q0 = cj.R_zero * (markers[m] - cj.c_child);
      Vec3 d = R_pw * (pts[labels[m]].X_world - c_w);
      q0 -= a.dot(q0) * a;
      d -= a.dot(d) * a;
      if (q0.norm() < 1e-6 || d.norm() < 1e-6) continue;  // on the axis: no angle
      R = model_.hinge_rotation(j, std::atan2(a.dot(q0.cross(d)), q0.dot(d)));
      return true;
    }
    return false;
  }
  // Ball: Kabsch about the joint centre (the centre is the fixed point).
  Mat3 S = Mat3::Zero();
  for (std::size_t m = 0; m < markers.size(); ++m) {
    if (labels[m] < 0) continue;
    S += (R_pw * (pts[labels[m]].X_world - c_w)) * (markers[m] - cj.c_child).transpose();
  }
  const Eigen::JacobiSVD<Mat3> svd(S, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Mat3 D = Mat3::Identity();
  D(2, 2) = (svd.matrixU() * svd.matrixV().transpose()).determinant() < 0.0 ? -1.0 : 1.0;
  R = svd.matrixU() * D * svd.matrixV().transpose();
  return R.allFinite();
}

}  // namespace mocap
