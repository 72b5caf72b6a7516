// Design: see rate_evaluation.h.
#include "track/rate_evaluation.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <utility>

namespace mocap {
namespace {

double wrap_deg(double a) noexcept { return std::remainder(a, 360.0); }

const std::string& key_of(const AngleRow& r) noexcept { return r.joint; }
const std::string& key_of(const PoseRow& r) noexcept { return r.body; }

struct Sums {
  std::int64_t n = 0;
  double sq = 0.0, sq_sd = 0.0, max = 0.0;
  void add(double err, double sd) noexcept {
    ++n;
    sq += err * err;
    sq_sd += sd * sd;
    max = std::max(max, std::abs(err));
  }
  RateStats stats() const noexcept {
    RateStats r;
    r.samples = n;
    if (n == 0) return r;
    r.rms = std::sqrt(sq / static_cast<double>(n));
    r.rms_sd = std::sqrt(sq_sd / static_cast<double>(n));
    r.max = max;
    r.sd_ratio = r.rms > 0.0 ? r.rms_sd / r.rms : 0.0;
    return r;
  }
  void into(JointRateError& e) const noexcept {
    const RateStats r = stats();
    e.samples = r.samples;
    e.rms_deg_s = r.rms;
    e.rms_sd_deg_s = r.rms_sd;
    e.max_deg_s = r.max;
    e.sd_ratio = r.sd_ratio;
  }
};

// The central-difference step of frame t: its two neighbours, equally spaced within 10 %.
template <typename Row, typename Map>
bool neighbours(const Map& at, const Row& t, const Row*& before, const Row*& after, double& dt_s) {
  const auto b = at.find({t.frame - 1, key_of(t)});
  const auto a = at.find({t.frame + 1, key_of(t)});
  if (b == at.end() || a == at.end()) return false;
  const double dt0 = static_cast<double>(t.timestamp_ns - b->second->timestamp_ns) * 1e-9;
  const double dt1 = static_cast<double>(a->second->timestamp_ns - t.timestamp_ns) * 1e-9;
  if (dt0 <= 0.0 || dt1 <= 0.0 || std::abs(dt0 - dt1) > 0.1 * std::max(dt0, dt1)) return false;
  before = b->second;
  after = a->second;
  dt_s = dt0 + dt1;
  return true;
}

}  // namespace

std::vector<JointRateError> rate_errors(const std::vector<AngleRow>& truth,
                                        const std::vector<AngleRow>& measured,
                                        JointRateError* all) {
  std::map<std::pair<std::int64_t, std::string>, const AngleRow*> meas, true_at;
  for (const AngleRow& m : measured) meas[{m.frame, m.joint}] = &m;
  for (const AngleRow& t : truth) true_at[{t.frame, t.joint}] = &t;
  std::vector<JointRateError> out;
  std::vector<Sums> sums;
  std::map<std::string, std::size_t> index;
  Sums pooled;
  for (const AngleRow& t : truth) {
    auto [it, inserted] = index.try_emplace(t.joint, out.size());
    if (inserted) {
      JointRateError e;
      e.joint = t.joint;
      e.type = t.type;
      out.push_back(e);
      sums.emplace_back();
    }
    const auto m = meas.find({t.frame, t.joint});
    if (m == meas.end() || !m->second->has_rates) continue;
    const AngleRow* before = nullptr;
    const AngleRow* after = nullptr;
    double dt = 0.0;
    if (!neighbours(true_at, t, before, after, dt)) continue;
    const int dofs = t.type == JointType::kHinge ? 1 : 3;
    for (int k = 0; k < dofs; ++k) {
      const double true_rate = wrap_deg(after->angles_deg(k) - before->angles_deg(k)) / dt;
      const double err = m->second->rate_deg_s(k) - true_rate;
      const double sd = m->second->rate_sd_deg_s(k);
      sums[it->second].add(err, sd);
      pooled.add(err, sd);
    }
  }
  for (std::size_t k = 0; k < out.size(); ++k) sums[k].into(out[k]);
  if (all != nullptr) {
    *all = JointRateError{};
    all->joint = "all";
    pooled.into(*all);
  }
  return out;
}

std::vector<BodyRateError> body_rate_errors(const std::vector<PoseRow>& truth,
                                            const std::vector<PoseRow>& measured,
                                            BodyRateError* all) {
  std::map<std::pair<std::int64_t, std::string>, const PoseRow*> meas, true_at;
  for (const PoseRow& m : measured) meas[{m.frame, m.body}] = &m;
  for (const PoseRow& t : truth) true_at[{t.frame, t.body}] = &t;
  std::vector<BodyRateError> out;
  std::vector<std::pair<Sums, Sums>> sums;
  std::map<std::string, std::size_t> index;
  Sums pooled_v, pooled_w;
  constexpr double kDeg = 180.0 / 3.14159265358979323846;
  for (const PoseRow& t : truth) {
    auto [it, inserted] = index.try_emplace(t.body, out.size());
    if (inserted) {
      out.push_back(BodyRateError{t.body, {}, {}});
      sums.emplace_back();
    }
    const auto m = meas.find({t.frame, t.body});
    if (m == meas.end() || !m->second->has_velocity) continue;
    const PoseRow* before = nullptr;
    const PoseRow* after = nullptr;
    double dt = 0.0;
    if (!neighbours(true_at, t, before, after, dt)) continue;
    const Vec3 v_true = (after->t_world_body - before->t_world_body) / dt;
    const Eigen::AngleAxisd turn(after->q_world_body * before->q_world_body.conjugate());
    const Vec3 w_true = turn.axis() * (turn.angle() * kDeg / dt);
    const PoseRow& r = *m->second;
    for (int k = 0; k < 3; ++k) {
      sums[it->second].first.add(r.v_world_mm_s[k] - v_true[k], r.v_sd_mm_s[k]);
      pooled_v.add(r.v_world_mm_s[k] - v_true[k], r.v_sd_mm_s[k]);
      sums[it->second].second.add(r.w_world_deg_s[k] - w_true[k], r.w_sd_deg_s[k]);
      pooled_w.add(r.w_world_deg_s[k] - w_true[k], r.w_sd_deg_s[k]);
    }
  }
  for (std::size_t k = 0; k < out.size(); ++k) {
    out[k].linear_mm_s = sums[k].first.stats();
    out[k].angular_deg_s = sums[k].second.stats();
  }
  if (all != nullptr) *all = BodyRateError{"all", pooled_v.stats(), pooled_w.stats()};
  return out;
}

}  // namespace mocap
