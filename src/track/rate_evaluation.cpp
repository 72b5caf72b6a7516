// Design: see rate_evaluation.h.
#include "track/rate_evaluation.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <utility>

namespace mocap {
namespace {

double wrap_deg(double a) noexcept { return std::remainder(a, 360.0); }

struct Sums {
  std::int64_t n = 0;
  double sq = 0.0, sq_sd = 0.0, max = 0.0;
  void add(double err, double sd) noexcept {
    ++n;
    sq += err * err;
    sq_sd += sd * sd;
    max = std::max(max, std::abs(err));
  }
  void into(JointRateError& e) const noexcept {
    e.samples = n;
    if (n == 0) return;
    e.rms_deg_s = std::sqrt(sq / static_cast<double>(n));
    e.rms_sd_deg_s = std::sqrt(sq_sd / static_cast<double>(n));
    e.max_deg_s = max;
    e.sd_ratio = e.rms_deg_s > 0.0 ? e.rms_sd_deg_s / e.rms_deg_s : 0.0;
  }
};

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
    const auto before = true_at.find({t.frame - 1, t.joint});
    const auto after = true_at.find({t.frame + 1, t.joint});
    if (before == true_at.end() || after == true_at.end()) continue;
    const double dt0 = static_cast<double>(t.timestamp_ns - before->second->timestamp_ns) * 1e-9;
    const double dt1 = static_cast<double>(after->second->timestamp_ns - t.timestamp_ns) * 1e-9;
    if (dt0 <= 0.0 || dt1 <= 0.0 || std::abs(dt0 - dt1) > 0.1 * std::max(dt0, dt1)) continue;
    const int dofs = t.type == JointType::kHinge ? 1 : 3;
    for (int k = 0; k < dofs; ++k) {
      const double true_rate =
          wrap_deg(after->second->angles_deg(k) - before->second->angles_deg(k)) / (dt0 + dt1);
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

}  // namespace mocap
