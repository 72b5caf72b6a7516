// Design: see lead.h.
#include "pipeline/publish/lead.h"

#include <cmath>

#include "core/rotation.h"

namespace mocap::publish {
namespace {

double wrap_to_pi(double a) noexcept {
  constexpr double kPi = 3.14159265358979323846;
  a = std::remainder(a, 2.0 * kPi);
  return a <= -kPi ? a + 2.0 * kPi : a;
}

void set_quat(client::JointRecord& r, const Quat& q) noexcept {
  const Quat c = q.w() < 0.0 ? Quat(-q.w(), -q.x(), -q.y(), -q.z()) : q;
  r.q[0] = static_cast<float>(c.w());
  r.q[1] = static_cast<float>(c.x());
  r.q[2] = static_cast<float>(c.y());
  r.q[3] = static_cast<float>(c.z());
}

}  // namespace

Expected<LeadPredictor> LeadPredictor::create(double lead_ms, const JointModel* model,
                                              const std::string& where) {
  if (!(std::isfinite(lead_ms) && lead_ms > 0.0 && lead_ms <= kMaxLeadMs))
    return Error{where + ": lead_ms: must be in (0, 50] milliseconds (the prediction horizon)"};
  LeadPredictor p;
  p.lead_ns_ = static_cast<std::int64_t>(std::llround(lead_ms * 1e6));
  if (model != nullptr) {
    if (model->joints.size() > client::kMaxJoints)
      return Error{where + ": lead_ms: the model has more joints than a message carries"};
    for (std::size_t j = 0; j < model->joints.size(); ++j)
      p.axis_parent_[j] = model->joints[j].axis_parent.normalized();
  }
  return p;
}

bool LeadPredictor::apply(const client::JointsMessage& in,
                          client::JointsMessage& out) const noexcept {
  out = in;
  client::JointPrediction pred;
  const std::int64_t t_ns = in.publish_ns + lead_ns_;
  const client::PredictStatus s = client::predict(in, t_ns, pred);
  if (s == client::PredictStatus::kBeyondHorizon) return false;
  out.flags |= client::kFlagPredicted;
  out.lead_us = static_cast<std::uint16_t>(lead_ns_ / 1000);
  for (std::uint16_t j = 0; j < pred.joint_count; ++j) {
    const client::PredictedJoint& p = pred.joints[j];
    if (!p.valid) continue;
    client::JointRecord& r = out.joints[j];
    for (int k = 0; k < 3; ++k) out.quality[j].sd_rad[k] = p.sd_rad[k];
    if (r.type == static_cast<std::uint8_t>(client::JointKind::kHinge)) {
      // Continuous as published: the change, not the wrapped angle.
      const double a_meas = static_cast<double>(in.joints[j].a[0]);
      const double da = wrap_to_pi(static_cast<double>(p.a_rad[0]) - a_meas);
      r.a[0] = static_cast<float>(a_meas + da);
      const float* q = in.joints[j].q;
      const Quat q_meas(static_cast<double>(q[0]), static_cast<double>(q[1]),
                        static_cast<double>(q[2]), static_cast<double>(q[3]));
      set_quat(r, Quat(Eigen::AngleAxisd(da, axis_parent_[j])) * q_meas.normalized());
    } else {
      for (int k = 0; k < 3; ++k) r.a[k] = p.a_rad[k];
      set_quat(r, canonical_quat(euler_xyz_to_rotation(Vec3(static_cast<double>(p.a_rad[0]),
                                                            static_cast<double>(p.a_rad[1]),
                                                            static_cast<double>(p.a_rad[2])))));
    }
  }
  return true;
}

}  // namespace mocap::publish
